# the linear delta end to end (issue 5): full per-step pipeline against bare mj_step on the
# delta, and the realtime factor of scenarios/giberti_circle.yaml
if(DEPOTWIN_WITH_MUJOCO)
  add_executable(bench_delta ${CMAKE_CURRENT_LIST_DIR}/bench_delta.cpp)
  target_link_libraries(bench_delta PRIVATE depotwin::pipeline benchmark::benchmark)
  target_compile_definitions(bench_delta PRIVATE DEPOTWIN_SCENARIOS_DIR="${DEPOTWIN_SCENARIOS_DIR}")
endif()

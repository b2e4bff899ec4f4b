# simulation and scene rendering (issue: XY stage twin): a bare mj_step loop against the full
# per-step run (controller + recording + on_step), and the render time per image
if(DEPOTWIN_WITH_MUJOCO)
  add_executable(bench_sim ${CMAKE_CURRENT_LIST_DIR}/bench_sim.cpp)
  target_link_libraries(bench_sim PRIVATE depotwin::sim depotwin::render depotwin::planners
                                          benchmark::benchmark)
  target_compile_definitions(bench_sim PRIVATE DEPOTWIN_MODELS_DIR="${DEPOTWIN_MODELS_DIR}")
endif()

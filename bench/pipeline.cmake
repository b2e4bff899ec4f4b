# the whole twin per step (issue: XY stage performance): bare mj_step against the full
# per-step pipeline as a ratio, the deposition kernel alone, the realtime factor of a
# thompson_fig7 run, and the render time per image
if(DEPOTWIN_WITH_MUJOCO)
  add_executable(bench_pipeline ${CMAKE_CURRENT_LIST_DIR}/bench_pipeline.cpp)
  target_link_libraries(bench_pipeline PRIVATE depotwin::pipeline benchmark::benchmark)
  target_compile_definitions(bench_pipeline PRIVATE DEPOTWIN_MODELS_DIR="${DEPOTWIN_MODELS_DIR}"
                                                    DEPOTWIN_SCENARIOS_DIR="${DEPOTWIN_SCENARIOS_DIR}")
endif()

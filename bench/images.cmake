# what images cost a run (issue: plots and renders must not dominate): `depotwin run
# thompson_fig7` with and without --no-render, timed alternately, as the share of wall time
if(DEPOTWIN_WITH_MUJOCO)
  add_executable(bench_images ${CMAKE_CURRENT_LIST_DIR}/bench_images.cpp)
  target_link_libraries(bench_images PRIVATE benchmark::benchmark)
  add_dependencies(bench_images depotwin)
  target_compile_definitions(bench_images PRIVATE DEPOTWIN_CLI="$<TARGET_FILE:depotwin>"
                                                  DEPOTWIN_SCENARIOS_DIR="${DEPOTWIN_SCENARIOS_DIR}")
endif()

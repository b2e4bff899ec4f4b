# minimum-time moves and lspb_mtt planning (issue 2)
add_executable(bench_motion ${CMAKE_CURRENT_LIST_DIR}/bench_motion.cpp)
target_link_libraries(bench_motion PRIVATE depotwin::planners benchmark::benchmark)

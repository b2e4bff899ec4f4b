# jerk-limited minimum-time moves: one axis and three synchronised axes
add_executable(bench_jerk ${CMAKE_CURRENT_LIST_DIR}/bench_jerk.cpp)
target_link_libraries(bench_jerk PRIVATE depotwin::motion benchmark::benchmark)

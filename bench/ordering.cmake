# print ordering (issue 6): the Table I reproduction program and the speed benchmarks
add_executable(ganganath_table ${CMAKE_CURRENT_LIST_DIR}/ordering_table.cpp)
target_link_libraries(ganganath_table PRIVATE depotwin::planners)
add_executable(bench_ordering ${CMAKE_CURRENT_LIST_DIR}/bench_ordering.cpp)
target_link_libraries(bench_ordering PRIVATE depotwin::planners benchmark::benchmark)

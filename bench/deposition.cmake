# deposition kernel: ns per 1 ms aerosol step and per extrusion step
add_executable(bench_deposition ${CMAKE_CURRENT_LIST_DIR}/bench_deposition.cpp)
target_link_libraries(bench_deposition PRIVATE depotwin::deposition benchmark::benchmark)

# No-heap proof for the core's real-time calls (allocation_test.cpp). Included from
# tests/core/CMakeLists.txt. Links only pliant::core (and the header-only pliant::core_testing,
# whose grid msm_fixture.hpp's lattice is): the counting operator new/delete and
# malloc interposition (tests/support/counting_allocator.cpp) are compiled into this one
# executable so they replace the allocator for it alone.
pliant_add_gtest(core_allocation_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/allocation_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/../support/counting_allocator.cpp
  LIBS pliant::core pliant::core_testing)
target_include_directories(core_allocation_test PRIVATE ${CMAKE_CURRENT_LIST_DIR}/..)
# Any dynamic Eigen allocation in the test's own code is reported (see allocation_test.cpp
# for why pliant::core itself is compiled without it).
target_compile_definitions(core_allocation_test PRIVATE EIGEN_RUNTIME_NO_MALLOC)

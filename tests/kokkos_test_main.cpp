// GoogleTest main for kushner's tests: Kokkos is initialized once for the whole binary.
#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>

#include <cstdlib>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  setenv("OMP_PROC_BIND", "false", 0);  // Kokkos 3.4 warns on stdout otherwise
  Kokkos::ScopeGuard kokkos(argc, argv);
  return RUN_ALL_TESTS();
}

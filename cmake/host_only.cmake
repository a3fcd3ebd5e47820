# kushner_host_only(<file>...): in CUDA builds these sources, which include no Kokkos header and hold no device
# code, go to the host compiler alone (nvcc_wrapper --host-only): nvcc would run its two front ends over them for
# nothing (engine/least_squares.cpp in CI's compile check: 23.7 s -> 11.1 s). A file that comes to include Kokkos
# must leave its list (Kokkos' CUDA headers need nvcc).
function(kushner_host_only)
  if(CMAKE_CXX_COMPILER MATCHES "nvcc_wrapper")
    set_source_files_properties(${ARGN} PROPERTIES COMPILE_OPTIONS "--host-only")
  endif()
endfunction()

# kushner_host_only(<file>...): in CUDA builds these sources, which include no Kokkos header and hold no device
# code, go to the host compiler alone (nvcc_wrapper --host-only): nvcc would run its two front ends over them for
# nothing (engine/least_squares.cpp in CI's compile check: 23.7 s -> 11.1 s). A file that comes to include Kokkos
# must leave its list (Kokkos' CUDA headers need nvcc).
# CI's compile check (KUSHNER_CUDA_COMPILE_CHECK) does not compile them at all: nothing links there, and the host
# build has already compiled the same code with the same g++ (they were 36 of its 516 core-s on the GPU machine).
function(kushner_host_only)
  if(KUSHNER_ENABLE_CUDA AND KUSHNER_CUDA_COMPILE_CHECK)
    set_source_files_properties(${ARGN} PROPERTIES HEADER_FILE_ONLY ON)
  elseif(CMAKE_CXX_COMPILER MATCHES "nvcc_wrapper")
    set_source_files_properties(${ARGN} PROPERTIES COMPILE_OPTIONS "--host-only")
  endif()
endfunction()

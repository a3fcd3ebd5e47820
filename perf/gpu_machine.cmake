# The GPU machine's CUDA builds (perf/run_*_gpu.sh: `cmake -C perf/gpu_machine.cmake ...`), where a command may run
# 10 minutes and the build has 16 or 32 cores: the device code compiled once, for the H100/H200 alone; each model's
# shared banks in a unit of its own, so that the longest unit, not a share of the models, sets the build's length
# (with 6 units, one of 4 models, cubic-oscillator, terpolymer, clark-quintic and a polynomial file model, ran
# past 520 s alone on an H200 machine's core: the full build did not fit a 10-minute call on 32 cores).
set(KUSHNER_CUDA_EXTRA_SASS "sm_90" CACHE STRING "")
set(KUSHNER_CUDA_EXTRA_SASS_ONLY ON CACHE BOOL "")
set(KUSHNER_INSTANCE_UNITS 22 CACHE STRING "")
set(KUSHNER_COMMAND_UNITS 16 CACHE STRING "")
# perf/run_gpu_validation.sh runs 8 tests at a time with 2 host threads each (OMP_NUM_THREADS=2 ctest -j8): each
# asks ctest for 2 cores, not all 16 (tests/CMakeLists.txt).
set(KUSHNER_TEST_PROCESSORS 2 CACHE STRING "")

# The fuzz build's compiler (tests/fuzz: CMake option AF_FUZZ): clang, whose libFuzzer the fuzz targets link.
#   cmake -S . -B build/fuzz -DCMAKE_TOOLCHAIN_FILE=cmake/clang.cmake -DAF_FUZZ=ON -DAF_PYTHON=OFF
# (Debian: apt-get install clang libclang-rt-dev). Configuring fails where there is no clang, or (CMakeLists.txt,
# AF_FUZZ) where it has no libFuzzer: tests/fuzz/run.py then builds the targets' own driver instead.
find_program(AF_CLANG NAMES clang clang-19 clang-18 clang-17 clang-16 clang-15 clang-14)
if(NOT AF_CLANG)
  message(FATAL_ERROR "cmake/clang.cmake: no clang on PATH (Debian: apt-get install clang libclang-rt-dev)")
endif()
set(CMAKE_C_COMPILER ${AF_CLANG})

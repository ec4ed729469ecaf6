# A cross build with zig's C compiler (the `ziglang` package ships it: pip install ziglang):
#   cmake -S . -B build/platform-x86_64-windows -DCMAKE_TOOLCHAIN_FILE=cmake/zig.cmake -DAF_ZIG_TARGET=x86_64-windows-gnu
#         -DPython_EXECUTABLE=... -DAF_PYTHON=OFF
# AF_ZIG_TARGET: zig's target triple (x86_64-linux-gnu.2.17, aarch64-linux-gnu.2.17, x86_64-windows-gnu,
# x86_64-macos, aarch64-macos); AF_ZIG: the zig executable (default: the ziglang package of Python_EXECUTABLE,
# else zig on PATH). CMake takes one compiler executable, so the build folder gets small wrapper scripts
# (zig/cc, zig/ar, zig/ranlib) that run `zig cc -target AF_ZIG_TARGET` and the others. C only: a cross
# build has no Python extension (AF_PYTHON OFF).
set(CMAKE_TRY_COMPILE_PLATFORM_VARIABLES AF_ZIG_TARGET AF_ZIG AF_ZIG_WRAPPERS)

if(NOT AF_ZIG_TARGET)
  message(FATAL_ERROR "cmake/zig.cmake needs -DAF_ZIG_TARGET=<zig target>, e.g. x86_64-windows-gnu")
endif()
if(AF_ZIG_TARGET MATCHES "^([a-z0-9_]+)-([a-z]+)")
  set(arch ${CMAKE_MATCH_1})
  set(os ${CMAKE_MATCH_2})
else()
  message(FATAL_ERROR "AF_ZIG_TARGET=${AF_ZIG_TARGET}: not a zig target <arch>-<os>[-<abi>]")
endif()
set(CMAKE_SYSTEM_PROCESSOR ${arch})
if(os STREQUAL "linux")
  set(CMAKE_SYSTEM_NAME Linux)
elseif(os STREQUAL "windows")
  set(CMAKE_SYSTEM_NAME Windows)
elseif(os STREQUAL "macos")
  set(CMAKE_SYSTEM_NAME Darwin)
else()
  message(FATAL_ERROR "AF_ZIG_TARGET=${AF_ZIG_TARGET}: cmake/zig.cmake knows the systems linux, windows, macos")
endif()

if(NOT AF_ZIG)
  if(Python_EXECUTABLE)
    execute_process(COMMAND ${Python_EXECUTABLE} -c
                            "import os, ziglang; print(os.path.join(os.path.dirname(ziglang.__file__), 'zig'))"
                    OUTPUT_VARIABLE zig OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  endif()
  if(NOT zig OR NOT EXISTS "${zig}")
    find_program(zig zig)
  endif()
  if(NOT zig)
    message(FATAL_ERROR "no zig: pip install ziglang (for -DPython_EXECUTABLE=), or give -DAF_ZIG=<zig executable>")
  endif()
  set(AF_ZIG ${zig} CACHE FILEPATH "the zig executable of the cross build")
endif()

if(NOT AF_ZIG_WRAPPERS)
  set(AF_ZIG_WRAPPERS ${CMAKE_BINARY_DIR}/zig)
endif()
foreach(tool "cc" "ar" "ranlib")
  set(arguments ${tool})
  if(tool STREQUAL "cc")
    set(arguments "${tool} -target ${AF_ZIG_TARGET}")
  endif()
  if(NOT EXISTS ${AF_ZIG_WRAPPERS}/${tool})
    file(WRITE ${AF_ZIG_WRAPPERS}/${tool}.new "#!/bin/sh\nexec \"${AF_ZIG}\" ${arguments} \"$@\"\n")
    file(CHMOD ${AF_ZIG_WRAPPERS}/${tool}.new PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ
               GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
    file(RENAME ${AF_ZIG_WRAPPERS}/${tool}.new ${AF_ZIG_WRAPPERS}/${tool})
  endif()
endforeach()
set(CMAKE_C_COMPILER ${AF_ZIG_WRAPPERS}/cc)
# no fused multiply-adds (clang contracts a*b+c on aarch64): every platform's binary rounds each product as
# x86-64's does, so that their outputs differ by no more than their math libraries do
set(CMAKE_C_FLAGS_INIT "-ffp-contract=off")
set(CMAKE_MODULE_LINKER_FLAGS_INIT "-s")  # the FMUs' binaries stripped (zig's runtime libraries carry debug info)
set(CMAKE_AR ${AF_ZIG_WRAPPERS}/ar CACHE FILEPATH "")
set(CMAKE_RANLIB ${AF_ZIG_WRAPPERS}/ranlib CACHE FILEPATH "")

# nothing of the build machine's is found for the target (its libraries, headers); programs (Python) are
set(CMAKE_FIND_ROOT_PATH ${AF_ZIG_WRAPPERS})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# the math library: glibc's libm, which zig provides for the target; part of the C library elsewhere
if(os STREQUAL "linux")
  set(AF_MATH m CACHE STRING "the math library")
endif()
# the FMUs' binaries folders for the target: FMI 3.0's platform tuple, FMI 2.0's folder (FMI 2.0 names none for
# aarch64: its tuple stands there, and the FMI 2.0 FMUs carry no such binary)
string(REPLACE "macos" "darwin" AF_FMI3_PLATFORM "${arch}-${os}")
set(AF_FMI2_PLATFORM ${AF_FMI3_PLATFORM})
if(arch STREQUAL "x86_64")
  string(REPLACE "macos" "darwin" AF_FMI2_PLATFORM "${os}64")
  string(REPLACE "windows" "win" AF_FMI2_PLATFORM "${AF_FMI2_PLATFORM}")
endif()

# CMake toolchain: Windows x86_64 from Debian 12 with MinGW-w64 (posix thread model), tests under Wine.
#   apt-get install --no-install-recommends g++-mingw-w64-x86-64-posix wine64
#   cmake -S . -B build-win -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake -DOSSA_RUNTIME_ONLY=ON
# scripts/test.sh builds the runtime and its suites this way and runs them under Wine.
#
# Why posix and not win32: the posix thread model gives std::thread / std::mutex (winpthreads);
# the win32 one lacks them in GCC 12. Why -static: the .exe needs no MinGW DLLs beside it, so Wine
# (or a Windows machine) runs it from the build tree as it is.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)

set(_mingw x86_64-w64-mingw32)
set(CMAKE_C_COMPILER   ${_mingw}-gcc-posix)
set(CMAKE_CXX_COMPILER ${_mingw}-g++-posix)
set(CMAKE_RC_COMPILER  ${_mingw}-windres)

# Find target headers/libraries/packages only under the MinGW tree (plus the header overlay below);
# host tools (flatc, python3, ...) are found on the host as usual.
set(CMAKE_FIND_ROOT_PATH /usr/${_mingw})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(CMAKE_FIND_USE_PACKAGE_REGISTRY OFF)
set(CMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY OFF)

# Header-only host libraries the Windows build may use. Never add /usr/include itself (glibc
# headers would shadow MinGW's): each allowed folder is symlinked into <build>/mingw-host-headers/
# include/, which is added to the find root, so find_path(... flatbuffers/flatbuffers.h) returns
# that folder and nothing else from /usr/include (and no Linux .so/.a or CMake package) is visible.
set(MINGW_HOST_HEADER_DIRS /usr/include/flatbuffers /usr/include/glm
    CACHE STRING "Host header-only library folders exposed to the MinGW build")
get_property(_mingw_in_try GLOBAL PROPERTY IN_TRY_COMPILE)
if(NOT _mingw_in_try)
  set(_overlay ${CMAKE_BINARY_DIR}/mingw-host-headers)
  file(MAKE_DIRECTORY ${_overlay}/include)
  foreach(_dir IN LISTS MINGW_HOST_HEADER_DIRS)
    get_filename_component(_name ${_dir} NAME)
    if(NOT IS_SYMLINK ${_overlay}/include/${_name})
      file(CREATE_LINK ${_dir} ${_overlay}/include/${_name} SYMBOLIC)
    endif()
  endforeach()
  list(APPEND CMAKE_FIND_ROOT_PATH ${_overlay})
endif()

# GCC cannot align the Win64 stack beyond 16 bytes for spills (GCC bug 54412): a spilled __m256 in
# target("avx2") code can land on a 16-byte boundary, and an aligned vmovaps/vmovdqa to it faults.
# The assembler rewrites aligned vector moves as unaligned ones (same speed on aligned data since
# Nehalem). A safety net: today's skinning kernels compile to unaligned moves even without it
# (objdump of skin_palette/skin_x86/skin_x86_batch.cpp.obj: no vmovaps/vmovdqa), but a future kernel
# or compiler might not.
set(CMAKE_C_FLAGS_INIT "-Wa,-muse-unaligned-vector-move")
set(CMAKE_CXX_FLAGS_INIT "-Wa,-muse-unaligned-vector-move")

# No libgcc_s/libstdc++/libwinpthread DLLs next to the .exe: link the runtime statically.
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static-libgcc -static-libstdc++")
set(CMAKE_MODULE_LINKER_FLAGS_INIT "-static-libgcc -static-libstdc++")

# Run target executables (ctest, gtest_discover_tests, add_custom_command) under Wine, headless, via
# wine-run.sh (next to this file; it sets WINEDEBUG/WINEDLLOVERRIDES, unsets DISPLAY and keeps Wine's
# background processes off CTest's output pipe). One Wine prefix per build tree unless WINEPREFIX is
# set when configuring. Debian's wine64 package installs /usr/lib/wine/wine64 (the 'wine' package
# adds /usr/bin/wine).
find_program(MINGW_WINE NAMES wine64 wine PATHS /usr/lib/wine NO_CMAKE_FIND_ROOT_PATH)
if(MINGW_WINE)
  if(DEFINED ENV{WINEPREFIX})
    set(MINGW_WINEPREFIX $ENV{WINEPREFIX} CACHE PATH "WINEPREFIX the tests run in")
  else()
    set(MINGW_WINEPREFIX ${CMAKE_BINARY_DIR}/wineprefix CACHE PATH "WINEPREFIX the tests run in")
  endif()
  set(CMAKE_CROSSCOMPILING_EMULATOR
      ${CMAKE_COMMAND} -E env WINEPREFIX=${MINGW_WINEPREFIX} WINE=${MINGW_WINE}
      ${CMAKE_CURRENT_LIST_DIR}/wine-run.sh)
endif()

# Cross-compiling for 64-bit Arm Linux (Jetson Orin / Thor's Arm cores) on a Debian x86-64 host with Debian's
# cross toolchain (g++-aarch64-linux-gnu) and the target's libraries from multiarch packages (libhwy-dev:arm64,
# libgtest-dev:arm64, ...: /usr/lib/aarch64-linux-gnu; /usr/include is shared between architectures). The test
# binaries run under qemu-user, so ctest and gtest_discover_tests work as on the host. scripts/test-aarch64.sh
# installs all of it and uses this file through the `aarch64` preset.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(_pyrseg_triplet aarch64-linux-gnu)
set(CMAKE_C_COMPILER ${_pyrseg_triplet}-gcc)
set(CMAKE_CXX_COMPILER ${_pyrseg_triplet}-g++)
# Multiarch: find_library and find_package look in <prefix>/lib/aarch64-linux-gnu (and its cmake/ folders), never
# in the host's /usr/lib/x86_64-linux-gnu. CMake derives this from the compiler too; set it for the first checks.
set(CMAKE_LIBRARY_ARCHITECTURE ${_pyrseg_triplet})

# Headers, libraries and CMake packages are looked for under the cross toolchain's own root (libc6-dev-arm64-cross)
# and /usr only, the arm64 ones by the library architecture above; programs (ninja, ...) are the host's.
set(CMAKE_FIND_ROOT_PATH /usr/${_pyrseg_triplet} /usr)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# pkg-config, where a find module asks it: the target's .pc files, not the host's.
if(EXISTS /usr/bin/${_pyrseg_triplet}-pkg-config)
  set(PKG_CONFIG_EXECUTABLE /usr/bin/${_pyrseg_triplet}-pkg-config CACHE FILEPATH "pkg-config for ${_pyrseg_triplet}")
endif()

# Run the target's programs (tests, gtest_discover_tests' listing) under qemu-user. The loader and libraries are
# the multiarch ones (libc6:arm64, which every :arm64 package pulls in: /lib/ld-linux-aarch64.so.1), found at the
# paths the binaries name, so qemu needs no -L: qemu 7.2 (bookworm) with -L /usr/aarch64-linux-gnu hangs a guest in
# its first pthread_create, which the CPU backend's thread pool calls in every Segmenter. Without libc6:arm64 the
# cross toolchain's loader runs the program itself, over the cross libraries and the multiarch ones.
find_program(PYRSEG_QEMU_AARCH64 NAMES qemu-aarch64 qemu-aarch64-static
             DOC "qemu-user for aarch64, which runs the cross-built tests")
if(PYRSEG_QEMU_AARCH64)
  if(EXISTS /lib/ld-linux-aarch64.so.1)
    set(CMAKE_CROSSCOMPILING_EMULATOR ${PYRSEG_QEMU_AARCH64})
  else()
    set(CMAKE_CROSSCOMPILING_EMULATOR ${PYRSEG_QEMU_AARCH64} /usr/${_pyrseg_triplet}/lib/ld-linux-aarch64.so.1
        --library-path /usr/${_pyrseg_triplet}/lib:/usr/lib/${_pyrseg_triplet})
  endif()
endif()

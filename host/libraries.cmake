# The host's sources and the libraries they need beyond core and the SDK, in one place for the
# program (host/CMakeLists.txt) and for the scene fuzzer, which compiles the host's sources itself
# with clang and its sanitizers (tests/fuzz/CMakeLists.txt): a library the host gains is then the
# fuzzer's too (the fuzzer once failed to build for want of the HDF5 writer's library, and
# nothing noticed). Sets VARIA_HOST_SOURCES (without main.cpp) and VARIA_HOST_LIBRARIES.
find_package(fmt REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
# The trajectory's HDF5 output (--out FILE.h5): the HDF5 C library (Debian: libhdf5-dev), found
# through pkg-config (CMake's FindHDF5 wants the C language enabled, which this C++ project is not).
find_package(PkgConfig REQUIRED)
pkg_check_modules(HDF5 REQUIRED IMPORTED_TARGET GLOBAL hdf5)
# `varia ensemble` under mpirun: Open MPI's C interface (Debian: libopenmpi-dev), through pkg-config.
pkg_check_modules(MPI REQUIRED IMPORTED_TARGET GLOBAL mpi-c)
set(VARIA_HOST_LIBRARIES fmt::fmt CLI11::CLI11 PkgConfig::HDF5 PkgConfig::MPI ${CMAKE_DL_LIBS})
file(GLOB VARIA_HOST_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/src/*.cpp
     ${CMAKE_CURRENT_LIST_DIR}/src/constructions/*.cpp)
list(FILTER VARIA_HOST_SOURCES EXCLUDE REGEX "/main\\.cpp$")

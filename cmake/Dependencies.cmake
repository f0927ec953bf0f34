# Every third-party dependency, found as a Debian 12 package (see docs/install.md).
find_package(Simbody 3.7 CONFIG REQUIRED)
find_package(Eigen3 3.4 CONFIG REQUIRED)
find_package(SUNDIALS 6.4 CONFIG REQUIRED COMPONENTS cvodes)
find_package(Ceres 2.1 CONFIG REQUIRED)
find_package(HDF5 REQUIRED COMPONENTS C CXX)
find_package(yaml-cpp CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(fmt CONFIG REQUIRED)
find_package(nlohmann_json 3.11 CONFIG REQUIRED)
find_package(muparser 2.3 CONFIG REQUIRED)
# Header-only: Boost.Math's F and chi-square distributions (global search, credibility).
find_package(Boost 1.74 REQUIRED)

# Trap 1 (docs/toolchain): libSimTKmath carries a private, incompatible copy of SUNDIALS'
# N_V* symbols. Linking CVODES as a whole static archive with its symbols kept private makes
# every CVODES call resolve to CVODES and every Simbody call to Simbody, in any link order.
add_library(mbid_cvodes INTERFACE)
target_link_libraries(mbid_cvodes INTERFACE
  "$<LINK_LIBRARY:WHOLE_ARCHIVE,SUNDIALS::cvodes_static>")
# clang's libFuzzer and ASan runtimes crash at start-up when their own archives' symbols are
# hidden too, so the fuzz build hides CVODES' archive only.
if(MBID_FUZZ)
  target_link_options(mbid_cvodes INTERFACE "LINKER:--exclude-libs,libsundials_cvodes.a")
else()
  target_link_options(mbid_cvodes INTERFACE "LINKER:--exclude-libs,ALL")
endif()

# Trap 2: Debian built Simbody without NDEBUG, and SimTK::CacheEntryInfo changes layout with
# it. Every target that sees Simbody headers compiles with NDEBUG undefined (checked at compile
# time in mbid/model/simbody_fwd.h); Eigen's asserts stay off in optimized builds.
add_library(mbid_simbody INTERFACE)
target_link_libraries(mbid_simbody INTERFACE SimTKsimbody SimTKmath SimTKcommon)
target_compile_options(mbid_simbody INTERFACE -UNDEBUG)
target_compile_definitions(mbid_simbody INTERFACE
  "$<$<NOT:$<CONFIG:Debug>>:EIGEN_NO_DEBUG>")

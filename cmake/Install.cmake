# `cmake --install build --prefix P`: the libraries and their headers, the mbid binary, the
# scenarios and docs under share/mbid, and a CMake package: find_package(mbid CONFIG REQUIRED)
# then target_link_libraries(x PRIVATE mbid::mbid).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(MBID_LIBRARIES mbid_common mbid_records mbid_model mbid_simulation mbid_identification
  mbid_updating mbid_validation mbid_report mbid_campaign mbid_facade)
# Each library's public headers live in <library>/include; installed, they share include/.
foreach(library ${MBID_LIBRARIES})
  get_target_property(source_dir ${library} SOURCE_DIR)
  set_target_properties(${library} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES
    "$<BUILD_INTERFACE:${source_dir}/include>;$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  install(DIRECTORY "${source_dir}/include/" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
          FILES_MATCHING PATTERN "*.h")
endforeach()
# mbid_simbody (-UNDEBUG for Simbody's headers, trap 2) and mbid_cvodes (CVODES as a private
# whole archive, trap 1) travel with the exported targets, so consumers inherit both fixes.
install(TARGETS ${MBID_LIBRARIES} mbid_simbody mbid_cvodes mbid_warnings
  EXPORT mbidTargets
  ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
  LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(TARGETS mbid RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
install(EXPORT mbidTargets NAMESPACE mbid:: DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/mbid")

install(DIRECTORY "${MBID_SOURCE_DIR}/scenarios" DESTINATION "${CMAKE_INSTALL_DATADIR}/mbid")
install(DIRECTORY "${MBID_SOURCE_DIR}/docs" DESTINATION "${CMAKE_INSTALL_DATADIR}/mbid")
# docs/library.md and docs/python.md link the examples beside them.
install(DIRECTORY "${MBID_SOURCE_DIR}/examples" DESTINATION "${CMAKE_INSTALL_DATADIR}/mbid"
  REGEX "examples/CMakeLists.txt$" EXCLUDE)
install(FILES "${MBID_SOURCE_DIR}/README.md" DESTINATION "${CMAKE_INSTALL_DATADIR}/mbid")

# The package's own dependencies are found again in the consumer (the static libraries carry
# them on their link lines).
find_package(MPI COMPONENTS CXX QUIET)
set(MBID_WITH_MPI ${MPI_CXX_FOUND})
configure_package_config_file("${MBID_SOURCE_DIR}/cmake/mbidConfig.cmake.in"
  "${CMAKE_CURRENT_BINARY_DIR}/mbidConfig.cmake"
  INSTALL_DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/mbid")
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/mbidConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES "${CMAKE_CURRENT_BINARY_DIR}/mbidConfig.cmake"
  "${CMAKE_CURRENT_BINARY_DIR}/mbidConfigVersion.cmake"
  DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/mbid")

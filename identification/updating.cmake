# Model updating (issue 5): the paper's algebraic route (eqs. 6-8) and the time-domain
# output-error fit with Ceres, CVODES sensitivities from mbid_simulation. A target of its own so
# that it builds apart from the modal identifier; included from identification/CMakeLists.txt.
# Paths from CMAKE_CURRENT_LIST_DIR: the file works wherever it is included from.
set(MBID_UPDATING_DIR "${CMAKE_CURRENT_LIST_DIR}")
add_library(mbid_updating
  "${MBID_UPDATING_DIR}/src/updating/baseline.cc"
  "${MBID_UPDATING_DIR}/src/updating/characteristic.cc"
  "${MBID_UPDATING_DIR}/src/updating/credibility.cc"
  "${MBID_UPDATING_DIR}/src/updating/global_search.cc"
  "${MBID_UPDATING_DIR}/src/updating/fisher.cc"
  "${MBID_UPDATING_DIR}/src/updating/output_error.cc"
  "${MBID_UPDATING_DIR}/src/updating/plan.cc"
  "${MBID_UPDATING_DIR}/src/updating/result_io.cc"
  "${MBID_UPDATING_DIR}/src/updating/settings.cc"
  "${MBID_UPDATING_DIR}/src/updating/structure.cc")
target_include_directories(mbid_updating PUBLIC "${MBID_UPDATING_DIR}/include")
target_link_libraries(mbid_updating
  PUBLIC mbid_simulation mbid_model mbid_common
  PRIVATE Ceres::ceres fmt::fmt Boost::headers mbid_simbody mbid_cvodes mbid_warnings)

# The SDK for external controllers (docs/external-controllers.md, "C++: the SDK"):
# `cmake --install build --prefix P` installs the drive model, the plant (with CVODE), the
# controllers and the trajectories as libraries (static, or shared with -DBUILD_SHARED_LIBS=ON),
# their headers, the generated message headers and a CMake package, so that
#   find_package(feeddrive REQUIRED)   # with -DCMAKE_PREFIX_PATH=P
#   target_link_libraries(my_controller PRIVATE feeddrive::controller feeddrive::lcmtypes)
# works. feeddrive::controller needs feeddrive::model and feeddrive::trajectory only, not CVODE.
include(CMakePackageConfigHelpers)
set(FEEDDRIVE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/feeddrive)
# Shared builds: each installed library finds the others next to it ($ORIGIN), so a program that
# links only feeddrive::controller starts without LD_LIBRARY_PATH (its own RUNPATH does not reach
# the libraries its libraries need).
set_target_properties(feeddrive_common feeddrive_model feeddrive_plant feeddrive_controller feeddrive_trajectory
  feeddrive_lcmtypes PROPERTIES INSTALL_RPATH "$ORIGIN")
install(TARGETS feeddrive_common feeddrive_model feeddrive_plant feeddrive_controller feeddrive_trajectory feeddrive_lcmtypes
  feeddrive_plugin
  EXPORT feeddriveTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY
  ${PROJECT_SOURCE_DIR}/common/include/feeddrive
  ${PROJECT_SOURCE_DIR}/plant/include/feeddrive
  ${PROJECT_SOURCE_DIR}/controller/include/feeddrive
  ${PROJECT_SOURCE_DIR}/trajectory/include/feeddrive
  ${PROJECT_BINARY_DIR}/lcmtypes/include/feeddrive
  ${PROJECT_SOURCE_DIR}/lcmtypes/include/feeddrive
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lcmtypes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/feeddrive/lcmtypes
  FILES_MATCHING PATTERN "*.lcm")
install(EXPORT feeddriveTargets NAMESPACE feeddrive:: DESTINATION ${FEEDDRIVE_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/feeddriveConfig.cmake.in
  ${PROJECT_BINARY_DIR}/feeddriveConfig.cmake INSTALL_DESTINATION ${FEEDDRIVE_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/feeddriveConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/feeddriveConfig.cmake ${PROJECT_BINARY_DIR}/feeddriveConfigVersion.cmake
  DESTINATION ${FEEDDRIVE_CMAKE_DIR})

# The tools (docs/cli.md) into <prefix>/bin, side by side (feeddrive-launch finds its siblings
# next to itself). Static builds only: a tool links libraries the SDK does not install
# (feeddrive::sim, feeddrive::service, ...), which a shared build would leave it without.
# OPTIONAL: a tree built only in part (a consumer's SDK targets) installs the tools it has.
if(NOT BUILD_SHARED_LIBS)
  set(feeddrive_tools feeddrive-sim feeddrive-keys feeddrive-monitor feeddrive-log2csv feeddrive-plant
      feeddrive-controller feeddrive-trajectory feeddrive-launch feeddrive-study)
  if(FEEDDRIVE_WITH_FIT)
    list(APPEND feeddrive_tools feeddrive-fit)
  endif()
  install(TARGETS ${feeddrive_tools} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} OPTIONAL)
endif()

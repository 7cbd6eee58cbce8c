include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(skybake_targets skybake)
foreach(m IN LISTS SKYBAKE_MODULES)
  list(APPEND skybake_targets skybake_${m})
endforeach()
if(TARGET skybake_imgui_backends)
  list(APPEND skybake_targets skybake_imgui_backends)
endif()

install(TARGETS ${skybake_targets} EXPORT skybakeTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS skybake_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/skybake DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_BINARY_DIR}/include/skybake/version.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/skybake)
install(EXPORT skybakeTargets NAMESPACE skybake::
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/skybake)

configure_package_config_file(cmake/skybakeConfig.cmake.in
  ${PROJECT_BINARY_DIR}/skybakeConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/skybake)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/skybakeConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/skybakeConfig.cmake ${PROJECT_BINARY_DIR}/skybakeConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/skybake)

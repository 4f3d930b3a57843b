# `cmake --install build --prefix PREFIX`: the layer libraries, their headers, the sph program
# and its data, and the sph package, so that another CMake project can
#   find_package(sph 0.1 REQUIRED)
#   target_link_libraries(app PRIVATE sph::solver)     # any layer: sph::core ... sph::bench
# Installed layout (GNUInstallDirs):
#   bin/sph                                   the program (finds share/sph from its own location)
#   lib/libsph_<layer>.a                      one library per layer of SPH_LAYERS
#   include/sph/<layer>/*.h                   the headers, include/sph/core/version.h generated
#   share/sph/scenes/{paper,validation,dfsph}/ the scenes sph bench and sph validate run, and DFSPH's
#   lib/cmake/sph/sph{Config,ConfigVersion,Targets}.cmake   the package
include(CMakePackageConfigHelpers)

set(SPH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/sph CACHE STRING "Where the sph package files go (relative to the prefix)")

set(sph_layer_targets "")
foreach(layer IN LISTS SPH_LAYERS)
  list(APPEND sph_layer_targets sph_${layer})
  install(DIRECTORY src/sph/${layer}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sph/${layer}
          FILES_MATCHING PATTERN "*.h" PATTERN "viewer" EXCLUDE)
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/generated/sph/core/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sph/core)
install(TARGETS ${sph_layer_targets} EXPORT sphTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS sph EXPORT sphTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY scenes/paper scenes/validation scenes/dfsph scenes/examples DESTINATION ${CMAKE_INSTALL_DATADIR}/sph/scenes)

install(EXPORT sphTargets NAMESPACE sph:: DESTINATION ${SPH_INSTALL_CMAKEDIR})
configure_package_config_file(cmake/sphConfig.cmake.in ${PROJECT_BINARY_DIR}/sphConfig.cmake
                              INSTALL_DESTINATION ${SPH_INSTALL_CMAKEDIR})
# 0.x: a new minor version may break the API, so only the same major.minor is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sphConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sphConfig.cmake ${PROJECT_BINARY_DIR}/sphConfigVersion.cmake
        DESTINATION ${SPH_INSTALL_CMAKEDIR})

# `cmake --install`: the public headers, the libraries (one per layer, and saccade::saccade
# for all of them), the programs, the data (robots, scenes, pipelines, the web page) and a
# package configuration, so that another project can
#   find_package(saccade REQUIRED)
#   target_link_libraries(app PRIVATE saccade::saccade)
# The libraries are static: what they use privately (spdlog, Assimp, EGL, Boost, ...) is
# needed to link them but never seen by the consumer's compiler (no include path, no header
# of theirs in saccade's public headers); saccadeConfig.cmake finds it.
include(CMakePackageConfigHelpers)

# Everything at once, as users expect.
add_library(saccade_all INTERFACE)
set_target_properties(saccade_all PROPERTIES EXPORT_NAME saccade)
target_link_libraries(saccade_all INTERFACE ${SACCADE_MODULES})
add_library(saccade::saccade ALIAS saccade_all)

set(SACCADE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/saccade)
install(TARGETS ${SACCADE_MODULES} saccade_all saccade_opencv
        EXPORT saccadeTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS saccade saccade-servo-emulator RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/saccade DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT saccadeTargets NAMESPACE saccade:: DESTINATION ${SACCADE_CMAKE_DIR})
configure_package_config_file(cmake/saccadeConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/saccadeConfig.cmake
                              INSTALL_DESTINATION ${SACCADE_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/saccadeConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/saccadeConfig.cmake
              ${PROJECT_BINARY_DIR}/saccadeConfigVersion.cmake
        DESTINATION ${SACCADE_CMAKE_DIR})

# The data the programs read (apps/saccade/common.cc: ShippedFile), in share/saccade: the
# scenes refer to assets/ by relative paths.
set(SACCADE_SHARE ${CMAKE_INSTALL_DATADIR}/saccade)
install(DIRECTORY assets robots scenes pipelines DESTINATION ${SACCADE_SHARE})
install(DIRECTORY web/public DESTINATION ${SACCADE_SHARE}/web)
install(DIRECTORY web/node_modules/three/build web/node_modules/three/examples/jsm
        DESTINATION ${SACCADE_SHARE}/web/node_modules/three OPTIONAL)
install(FILES web/node_modules/three/LICENSE web/node_modules/three/package.json
        DESTINATION ${SACCADE_SHARE}/web/node_modules/three OPTIONAL)

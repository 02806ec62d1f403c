# install.cmake — what `cmake --install build --prefix P` puts where, and how a game finds it:
#   P/include/ossa/...                    public headers (+ generated ossa_generated.h, version.h)
#   P/lib/libossa_runtime.a, libossa_format.a
#   P/lib/cmake/ossa/ossaConfig.cmake     find_package(ossa CONFIG REQUIRED) -> ossa::runtime, ossa_cook()
#   P/lib/pkgconfig/ossa.pc               pkg-config --cflags --libs ossa
#   P/bin/ossa-cook, ossa-inspect, ...    the tools (component "tools")
#   P/share/ossa/ossa.fbs, P/share/doc/ossa/LICENSE
# The package config finds the runtime's two dependencies (FlatBuffers, GLM) itself, so a game's
# CMakeLists needs one find_package and one target_link_libraries.
include(CMakePackageConfigHelpers)

install(TARGETS ossa_format ossa_runtime EXPORT ossaTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(OSSA_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/ossa)
install(EXPORT ossaTargets NAMESPACE ossa:: DESTINATION ${OSSA_CMAKE_DIR} COMPONENT runtime)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ossaConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/ossaConfig.cmake INSTALL_DESTINATION ${OSSA_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ossaConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/ossaConfig.cmake ${PROJECT_BINARY_DIR}/ossaConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/ossaCook.cmake
        DESTINATION ${OSSA_CMAKE_DIR} COMPONENT runtime)

# The .pc file finds its prefix from its own location, so `cmake --install --prefix P` at any P works.
file(RELATIVE_PATH OSSA_PC_TO_PREFIX /P/${CMAKE_INSTALL_LIBDIR}/pkgconfig /P)
configure_file(${PROJECT_SOURCE_DIR}/cmake/ossa.pc.in ${PROJECT_BINARY_DIR}/ossa.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/ossa.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)

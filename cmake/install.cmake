# Install rules and the package configuration (included from the top-level CMakeLists.txt with WARPCHECK_INSTALL):
#   include/warpcheck/*.h               the kernels (lib/warpcheck/)
#   include/warpcheck/validation/*.h    the validation API (validation/include/warpcheck/validation/)
#   lib/libwarpcheck_validation.a       the battery (warpcheck::validation)
#   lib/libwarpcheck_catalogue.a        warpcheck's own kernels' registry, negative controls and searches
#                                       (warpcheck::catalogue)
#   lib/cmake/warpcheck/                warpcheckConfig.cmake, its version file and the exported targets
# The battery's, the catalogue's and the searches' own headers (validation/battery/*.h, ...) are not installed:
# the public headers never include them.
include(CMakePackageConfigHelpers)

set(WARPCHECK_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/warpcheck)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lib/warpcheck ${PROJECT_SOURCE_DIR}/validation/include/warpcheck
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT devel FILES_MATCHING PATTERN "*.h")
set(WARPCHECK_INSTALLED_TARGETS warpcheck_kernels warpcheck_validation)
if(WARPCHECK_BUILD_CATALOGUE)
  list(APPEND WARPCHECK_INSTALLED_TARGETS warpcheck_catalogue)
endif()
install(TARGETS ${WARPCHECK_INSTALLED_TARGETS} EXPORT warpcheckTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT devel)
install(EXPORT warpcheckTargets NAMESPACE warpcheck:: DESTINATION ${WARPCHECK_CMAKE_DIR} COMPONENT devel)

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/warpcheckConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/warpcheckConfig.cmake INSTALL_DESTINATION ${WARPCHECK_CMAKE_DIR})
# 0.x: a minor version may change the API, so only the same major.minor is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/warpcheckConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/warpcheckConfig.cmake ${PROJECT_BINARY_DIR}/warpcheckConfigVersion.cmake
        DESTINATION ${WARPCHECK_CMAKE_DIR} COMPONENT devel)

# `cpack -G DEB` in the build directory: a Debian package of the above (headers, library, CMake files).
set(CPACK_PACKAGE_NAME warpcheck-dev)
set(CPACK_PACKAGE_VENDOR warpcheck)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Light-sampling kernels and a statistical validation battery for samplers")
set(CPACK_PACKAGE_CONTACT "warpcheck maintainers")
set(CPACK_GENERATOR DEB)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libeigen3-dev (>= 3.4), libboost-dev (>= 1.81)")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)

# The Debian package (CPack): steadyxr_<version>_amd64.deb with the layer, both manifests, the
# IMU emulator, the `steadyxr` tool, an example config, the READMEs (with docs/, which the top README
# links to) and man pages.
#
#   cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j && (cd build && cpack -G DEB)
#
# The version is project(VERSION) in the top-level CMakeLists.txt, nowhere else.
include(GNUInstallDirs)

set(STEADYXR_DOC_DIR ${CMAKE_INSTALL_DATADIR}/doc/steadyxr)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${STEADYXR_DOC_DIR})
# docs/ beside README.md, so that the README's links into docs/ resolve in the installed folder too.
install(FILES ${PROJECT_SOURCE_DIR}/docs/ARCHITECTURE.md ${PROJECT_SOURCE_DIR}/docs/evaluation-corpus.md
              ${PROJECT_SOURCE_DIR}/docs/evaluation-scenes.md ${PROJECT_SOURCE_DIR}/docs/method-history.md
              ${PROJECT_SOURCE_DIR}/docs/cost.md
        DESTINATION ${STEADYXR_DOC_DIR}/docs)
install(FILES ${PROJECT_SOURCE_DIR}/layer/xr/README.md DESTINATION ${STEADYXR_DOC_DIR} RENAME README.layer.md)
install(FILES ${PROJECT_SOURCE_DIR}/imu/README.md DESTINATION ${STEADYXR_DOC_DIR} RENAME README.imu.md)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/copyright DESTINATION ${STEADYXR_DOC_DIR})
install(FILES ${PROJECT_SOURCE_DIR}/layer/xr/steadyxr.conf.example DESTINATION ${STEADYXR_DOC_DIR}/examples
        RENAME steadyxr.conf)

# Man pages, gzipped as Debian installs them (-n: no time stamp, so the package is reproducible).
find_program(GZIP_PROGRAM gzip REQUIRED)
set(steadyxr_man_pages)
foreach(page steadyxr.1 steadyxr-imu-emu.1)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/man/${page} ${PROJECT_BINARY_DIR}/man/${page} @ONLY)
  add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/man/${page}.gz
                     COMMAND ${GZIP_PROGRAM} -9nf -k ${PROJECT_BINARY_DIR}/man/${page}
                     DEPENDS ${PROJECT_BINARY_DIR}/man/${page} VERBATIM)
  list(APPEND steadyxr_man_pages ${PROJECT_BINARY_DIR}/man/${page}.gz)
endforeach()
add_custom_target(steadyxr_man ALL DEPENDS ${steadyxr_man_pages})
install(FILES ${steadyxr_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

if(TARGET steadyxr)
  install(TARGETS steadyxr RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
if(TARGET steadyxr-imu-emu)
  install(TARGETS steadyxr-imu-emu RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME steadyxr)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_CONTACT "steadyxr maintainers <steadyxr@invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "OpenXR API layer against head-jittered aliasing (TAA + stereo blending)")
# The extended description (CPack puts the summary above it as the synopsis).
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "steadyxr filters the eye images of Vulkan OpenXR applications before the runtime composites
them: head-movement-aware temporal anti-aliasing and stereo blending as Vulkan compute passes.
Enable it per app with STEADYXR_ENABLE=1; the steadyxr command switches it and its method live.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # steadyxr_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)  # Depends from dpkg-shlibdeps
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libopenxr-loader1, mesa-vulkan-drivers | vulkan-icd")
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)

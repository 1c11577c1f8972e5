# The viewer's page (viewer/ in the source tree) and three.js from the npm registry (pinned by
# viewer/package-lock.json), assembled in <build>/share/varslam/viewer where the binaries in <build>/bin find it,
# and installed to <prefix>/share/varslam/viewer. Nothing is fetched when the viewer runs.
find_package(PkgConfig REQUIRED)
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
find_program(NPM_PROGRAM npm)
if(NOT NPM_PROGRAM)
  message(FATAL_ERROR "the viewer needs npm to install three.js (apt-get install npm, or scripts/setup.sh); "
                      "-DVARSLAM_BUILD_VIEWER=OFF builds without the viewer")
endif()

set(VARSLAM_VIEWER_DIR "${CMAKE_BINARY_DIR}/share/varslam/viewer")
set(_npm_dir "${CMAKE_BINARY_DIR}/viewer-npm")
set(_three "${_npm_dir}/node_modules/three")
add_custom_command(
  OUTPUT "${_three}/build/three.module.js"
  COMMAND "${CMAKE_COMMAND}" -E make_directory "${_npm_dir}"
  COMMAND "${CMAKE_COMMAND}" -E copy "${CMAKE_SOURCE_DIR}/viewer/package.json" "${CMAKE_SOURCE_DIR}/viewer/package-lock.json" "${_npm_dir}/"
  COMMAND "${NPM_PROGRAM}" ci --prefix "${_npm_dir}" --no-audit --no-fund --loglevel=error
  COMMAND "${CMAKE_COMMAND}" -E touch "${_three}/build/three.module.js"
  DEPENDS "${CMAKE_SOURCE_DIR}/viewer/package.json" "${CMAKE_SOURCE_DIR}/viewer/package-lock.json"
  COMMENT "npm: installing three.js for the viewer"
  VERBATIM)

set(_page_files index.html viewer.js viewer.css)
set(_outputs)
foreach(f ${_page_files})
  add_custom_command(OUTPUT "${VARSLAM_VIEWER_DIR}/${f}"
    COMMAND "${CMAKE_COMMAND}" -E copy "${CMAKE_SOURCE_DIR}/viewer/${f}" "${VARSLAM_VIEWER_DIR}/${f}"
    DEPENDS "${CMAKE_SOURCE_DIR}/viewer/${f}" VERBATIM)
  list(APPEND _outputs "${VARSLAM_VIEWER_DIR}/${f}")
endforeach()
set(_three_files build/three.module.js build/three.core.js examples/jsm/controls/OrbitControls.js LICENSE)
foreach(f ${_three_files})
  get_filename_component(n "${f}" NAME)
  add_custom_command(OUTPUT "${VARSLAM_VIEWER_DIR}/three/${n}"
    COMMAND "${CMAKE_COMMAND}" -E copy "${_three}/${f}" "${VARSLAM_VIEWER_DIR}/three/${n}"
    DEPENDS "${_three}/build/three.module.js" VERBATIM)
  list(APPEND _outputs "${VARSLAM_VIEWER_DIR}/three/${n}")
endforeach()
add_custom_target(viewer_assets ALL DEPENDS ${_outputs})
install(DIRECTORY "${VARSLAM_VIEWER_DIR}/" DESTINATION "${CMAKE_INSTALL_DATADIR}/varslam/viewer")

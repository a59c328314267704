# cmake --install: the libraries, the headers, the CLI, the plotting scripts and a CMake package
# (find_package(bendlab) giving bendlab::bendlab and one bendlab::<stage> target per library).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

foreach(lib ${BENDLAB_LIBRARY_TARGETS})
  string(REPLACE "bendlab_" "" short ${lib})
  set_target_properties(${lib} PROPERTIES EXPORT_NAME ${short})
endforeach()
set(bendlab_installed_libraries ${BENDLAB_LIBRARY_TARGETS})
if(BENDLAB_MPI)
  set_target_properties(bendlab_parallel PROPERTIES EXPORT_NAME parallel)
  list(APPEND bendlab_installed_libraries bendlab_parallel)
  set(parallel_headers_excluded "")
else()
  set(parallel_headers_excluded PATTERN parallel EXCLUDE)
endif()
install(TARGETS ${bendlab_installed_libraries} bendlab EXPORT bendlabTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/bendlab DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} ${parallel_headers_excluded})
install(TARGETS bendlab_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The CLI finds its plotting scripts in <prefix>/share/bendlab/scripts (core/helper_program.hpp).
install(FILES ${PROJECT_SOURCE_DIR}/scripts/plot_rbc.py ${PROJECT_SOURCE_DIR}/scripts/plot_shear.py
              ${PROJECT_SOURCE_DIR}/scripts/plot_stretch.py ${PROJECT_SOURCE_DIR}/scripts/mills2004_stretch.csv
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bendlab/scripts)
install(EXPORT bendlabTargets NAMESPACE bendlab:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bendlab)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/bendlabConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/bendlabConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bendlab)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bendlabConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bendlabConfig.cmake ${PROJECT_BINARY_DIR}/bendlabConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bendlab)

# Install rules of the C++ library (docs/install.md):
#   <prefix>/include/abuopt/...                  the public headers of every layer
#   <prefix>/lib/libabuopt_*.a                    the layer libraries (static unless BUILD_SHARED_LIBS)
#   <prefix>/lib/cmake/abuopt/abuoptConfig.cmake  find_package(abuopt) with the targets
#       abuopt::common abuopt::core abuopt::surrogate abuopt::optimizer abuopt::problems abuopt::studies
#   <prefix>/bin/abuopt                           the command line
# The layers' include directories are the source folders in the build tree and <prefix>/include once
# installed; the layer CMakeLists stay as they are (this file rewrites the property for both).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ABUOPT_CMAKE_INSTALL_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/abuopt" CACHE STRING
    "Where abuoptConfig.cmake is installed (relative to the prefix)")

set(_abuopt_layers common core surrogate optimizer problems studies)
set(_abuopt_targets)
foreach(layer IN LISTS _abuopt_layers)
  set(tgt abuopt_${layer})
  list(APPEND _abuopt_targets ${tgt})
  # The same name in the build tree as in an installed package (studies has its alias already).
  if(NOT TARGET abuopt::${layer})
    add_library(abuopt::${layer} ALIAS ${tgt})
  endif()
  set_target_properties(${tgt} PROPERTIES EXPORT_NAME ${layer})
  get_target_property(_dirs ${tgt} INTERFACE_INCLUDE_DIRECTORIES)
  set(_wrapped)
  foreach(d IN LISTS _dirs)
    if(d MATCHES "^\\$<")
      list(APPEND _wrapped "${d}")          # already a generator expression
    else()
      list(APPEND _wrapped "$<BUILD_INTERFACE:${d}>")
      install(DIRECTORY "${d}/" DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
    endif()
  endforeach()
  list(APPEND _wrapped "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  set_target_properties(${tgt} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_wrapped}")
endforeach()

install(TARGETS ${_abuopt_targets} EXPORT abuoptTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS abuopt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT abuoptTargets NAMESPACE abuopt:: FILE abuoptTargets.cmake DESTINATION ${ABUOPT_CMAKE_INSTALL_DIR})

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/abuoptConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/abuoptConfig.cmake
                              INSTALL_DESTINATION ${ABUOPT_CMAKE_INSTALL_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/abuoptConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/abuoptConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/abuoptConfigVersion.cmake
        DESTINATION ${ABUOPT_CMAKE_INSTALL_DIR})

# What an installed abuopt needs beside its libraries (docs/install.md):
#   <prefix>/share/abuopt/configs/...     the shipped study configs: the installed `abuopt reproduce`
#                                         finds share/abuopt/configs/report by itself (from its binary)
#   <prefix>/share/abuopt/docs/...        the user guides (Markdown)
#   <prefix>/lib/pkgconfig/abuopt.pc      pkg-config --cflags --libs abuopt
# and the optional target `doc`: the API reference of the public headers with Doxygen (Debian's
# doxygen package; not part of the default build): cmake --build build --target doc.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/configs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/abuopt/configs
        FILES_MATCHING PATTERN "*.yaml" PATTERN "*.md")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/abuopt/docs)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/abuopt)

# The prefix relative to <libdir>/pkgconfig ("../.."), so the file is right for any install prefix.
file(RELATIVE_PATH ABUOPT_PC_TO_PREFIX "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
configure_file(${CMAKE_CURRENT_LIST_DIR}/abuopt.pc.in ${CMAKE_CURRENT_BINARY_DIR}/abuopt.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/abuopt.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

find_package(Doxygen QUIET)
if(DOXYGEN_FOUND)
  set(DOXYGEN_PROJECT_NAME "abuopt")
  set(DOXYGEN_PROJECT_NUMBER ${PROJECT_VERSION})
  set(DOXYGEN_PROJECT_BRIEF "Startup-profile design for Automatic Balancing Units: the public C++ headers")
  set(DOXYGEN_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/doc)
  set(DOXYGEN_GENERATE_HTML YES)
  set(DOXYGEN_GENERATE_LATEX NO)
  set(DOXYGEN_EXTRACT_ALL YES)          # the headers document with plain // comments
  set(DOXYGEN_JAVADOC_AUTOBRIEF YES)
  set(DOXYGEN_QUIET YES)
  set(DOXYGEN_WARNINGS NO)
  set(DOXYGEN_FULL_PATH_NAMES YES)
  set(DOXYGEN_STRIP_FROM_PATH ${PROJECT_SOURCE_DIR})
  set(DOXYGEN_STRIP_FROM_INC_PATH ${PROJECT_SOURCE_DIR}/common/include ${PROJECT_SOURCE_DIR}/core/include
      ${PROJECT_SOURCE_DIR}/surrogate/include ${PROJECT_SOURCE_DIR}/optimizer/include
      ${PROJECT_SOURCE_DIR}/problems/include ${PROJECT_SOURCE_DIR}/studies/include)
  set(DOXYGEN_USE_MDFILE_AS_MAINPAGE ${PROJECT_SOURCE_DIR}/docs/architecture.md)
  doxygen_add_docs(doc
    ${PROJECT_SOURCE_DIR}/docs/architecture.md
    ${PROJECT_SOURCE_DIR}/common/include ${PROJECT_SOURCE_DIR}/core/include ${PROJECT_SOURCE_DIR}/surrogate/include
    ${PROJECT_SOURCE_DIR}/optimizer/include ${PROJECT_SOURCE_DIR}/problems/include
    ${PROJECT_SOURCE_DIR}/studies/include
    COMMENT "API reference of the public headers: ${CMAKE_BINARY_DIR}/doc/html/index.html")
else()
  message(STATUS "abuopt: no doxygen: the API reference target `doc` is not available (Debian: doxygen)")
endif()

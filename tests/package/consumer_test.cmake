# cmake -P script of the test package_cpp_consumer: install, build the consumer, run it.
foreach(v BUILD_DIR SOURCE_DIR WORK_DIR CXX_COMPILER)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "consumer_test.cmake: -D${v}=... missing")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# The installed package must not point back into the source or build tree.
file(GLOB_RECURSE cmake_files ${prefix}/*.cmake)
foreach(f IN LISTS cmake_files)
  file(READ ${f} text)
  foreach(tree ${SOURCE_DIR} ${BUILD_DIR})
    string(FIND "${text}" "${tree}/" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${f} refers to ${tree}")
    endif()
  endforeach()
endforeach()
foreach(f include/abuopt/core/simulator.hpp include/abuopt/problems/startup_profile_problem.hpp
          include/abuopt/studies lib/cmake/abuopt/abuoptConfigVersion.cmake lib/cmake/abuopt/abuoptTargets.cmake
          include/abuopt/common/config_sections.hpp lib/pkgconfig/abuopt.pc share/abuopt/configs/report
          share/abuopt/configs/montecarlo_final_profile.yaml share/abuopt/docs/install.md)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${prefix}/${f}")
  endif()
endforeach()

# pkg-config finds the installed headers and libraries from the relocatable abuopt.pc.
find_program(PKG_CONFIG pkg-config)
if(PKG_CONFIG)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig
                          ${PKG_CONFIG} --variable=includedir abuopt
                  RESULT_VARIABLE rc OUTPUT_VARIABLE incdir OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0 OR NOT EXISTS "${incdir}/abuopt/core/simulator.hpp")
    message(FATAL_ERROR "pkg-config abuopt: includedir '${incdir}' holds no abuopt/core/simulator.hpp (${rc})")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig
                          ${PKG_CONFIG} --libs abuopt
                  RESULT_VARIABLE rc OUTPUT_VARIABLE libs)
  if(NOT rc EQUAL 0 OR NOT libs MATCHES "-labuopt_core")
    message(FATAL_ERROR "pkg-config --libs abuopt: ${libs} (${rc})")
  endif()
endif()

# The installed command finds its study files (share/abuopt/configs/report) from any directory.
file(MAKE_DIRECTORY ${WORK_DIR}/elsewhere)
execute_process(COMMAND ${prefix}/bin/abuopt reproduce --only final --runs 64 --threads 2 --no-plots --out repro
                WORKING_DIRECTORY ${WORK_DIR}/elsewhere RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "study files: ${prefix}/share/abuopt/configs/report")
  message(FATAL_ERROR "the installed abuopt reproduce --only final failed outside the source tree (${rc}):\n${out}\n${err}")
endif()
if(NOT EXISTS ${WORK_DIR}/elsewhere/repro/report.md)
  message(FATAL_ERROR "the installed abuopt reproduce wrote no report.md")
endif()
message("installed reproduce: ran from ${WORK_DIR}/elsewhere with ${prefix}/share/abuopt/configs/report")

set(launcher)
if(CXX_LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_LAUNCHER})
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/cpp/consumer -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} ${launcher})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/abuopt_consumer ${SOURCE_DIR}/configs/montecarlo_final_profile.yaml 0.5 2.0)
message("${last_output}")
if(NOT last_output MATCHES "status ok\nresidual imbalance \\|I_r\\| = [0-9.e+-]+e-7 kg m")
  message(FATAL_ERROR "unexpected consumer output")
endif()
message("consumer: residual imbalance printed by the out-of-tree build")

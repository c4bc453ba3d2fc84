# nadir_add_lcmtypes(<target> <file.lcm>...)
# Generates C++ headers with `lcm-gen -x` into the build tree (their decode()
# guarded against impossible counts: NadirLcmDecodeGuard.cmake) and exposes them
# through an INTERFACE target. Debian's LCM 1.3.1 has no lcmUtilities.cmake.
function(nadir_add_lcmtypes target)
  set(include_dir ${CMAKE_CURRENT_BINARY_DIR}/include)
  set(headers)
  foreach(lcm_file IN LISTS ARGN)
    get_filename_component(abs_file ${lcm_file} ABSOLUTE)
    file(READ ${abs_file} content)
    if(NOT content MATCHES "(^|\n)[ \t]*package[ \t]+([A-Za-z0-9_]+)")
      message(FATAL_ERROR "${lcm_file}: no package declaration")
    endif()
    set(package ${CMAKE_MATCH_2})
    get_filename_component(type_name ${lcm_file} NAME_WE)
    set(header ${include_dir}/${package}/${type_name}.hpp)
    add_custom_command(
      OUTPUT ${header}
      COMMAND ${LCM_GEN_EXECUTABLE} -x --cpp-hpath ${include_dir} ${abs_file}
      COMMAND ${CMAKE_COMMAND} -DHEADER=${header} -P ${PROJECT_SOURCE_DIR}/cmake/NadirLcmDecodeGuard.cmake
      DEPENDS ${abs_file} ${PROJECT_SOURCE_DIR}/cmake/NadirLcmDecodeGuard.cmake
      COMMENT "lcm-gen ${type_name}"
      VERBATIM)
    list(APPEND headers ${header})
  endforeach()
  add_custom_target(${target}_gen DEPENDS ${headers})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_gen)
  target_include_directories(${target} SYSTEM INTERFACE ${include_dir})
  target_link_libraries(${target} INTERFACE PkgConfig::LCM)
  # LCM 1.3.1's lcm_coretypes.h decodes doubles through an int64_t* cast. With
  # strict aliasing, -O3 can keep a field's value from before decode() (seen on
  # geodetic_position_t), so every user of the generated types compiles without it.
  target_compile_options(${target} INTERFACE -fno-strict-aliasing)
endfunction()

# The same types as Java classes in one jar, ${CMAKE_BINARY_DIR}/share/java/${jar_name}
# (beside bin/, as installed), for lcm-spy and every Java tool: built when a JDK
# and LCM's Java library (liblcm-java) are there, else said why not. Beside it,
# ${jar_name}.classpath names the jars it needs (lcm.jar; jchart2d.jar, for
# lcm-spy's charts, when there), one a line.
function(nadir_add_lcmtypes_jar target jar_name)
  find_package(Java 11 COMPONENTS Development QUIET)
  pkg_get_variable(lcm_jar lcm-java classpath)
  if(NOT Java_JAVAC_EXECUTABLE OR NOT Java_JAR_EXECUTABLE)
    message(STATUS "No ${jar_name}: no JDK (javac, jar); nadir spy needs it")
    return()
  endif()
  if(NOT lcm_jar OR NOT EXISTS "${lcm_jar}")
    message(STATUS "No ${jar_name}: no lcm.jar (liblcm-java); nadir spy needs it")
    return()
  endif()
  set(work ${CMAKE_CURRENT_BINARY_DIR}/java)
  set(jar_dir ${CMAKE_BINARY_DIR}/share/java)
  set(jar ${jar_dir}/${jar_name})
  set(classpath "${lcm_jar}\n")
  find_file(NADIR_JCHART2D_JAR jchart2d.jar PATHS /usr/share/java)
  if(NADIR_JCHART2D_JAR)
    string(APPEND classpath "${NADIR_JCHART2D_JAR}\n")
  endif()
  file(MAKE_DIRECTORY ${jar_dir})
  file(WRITE ${jar}.classpath "${classpath}")
  set(lcm_files)
  foreach(lcm_file IN LISTS ARGN)
    get_filename_component(abs_file ${lcm_file} ABSOLUTE)
    list(APPEND lcm_files ${abs_file})
  endforeach()
  add_custom_command(
    OUTPUT ${jar}
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${work}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${work}/src ${work}/classes
    COMMAND ${LCM_GEN_EXECUTABLE} -j --jpath ${work}/src ${lcm_files}
    COMMAND ${CMAKE_COMMAND} -DJAVAC=${Java_JAVAC_EXECUTABLE} -DCLASSPATH=${lcm_jar}
            -DSOURCES=${work}/src -DCLASSES=${work}/classes -P ${PROJECT_SOURCE_DIR}/cmake/NadirJavac.cmake
    COMMAND ${Java_JAR_EXECUTABLE} cf ${jar} -C ${work}/classes .
    DEPENDS ${lcm_files} ${PROJECT_SOURCE_DIR}/cmake/NadirJavac.cmake
    COMMENT "lcm-gen -j and javac: ${jar_name}"
    VERBATIM)
  add_custom_target(${target} ALL DEPENDS ${jar})
endfunction()

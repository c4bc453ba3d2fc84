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

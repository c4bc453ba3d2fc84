# nadir_set_warnings(<target>): the project's warning flags on one target.
function(nadir_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  # GCC's -Wshadow=local; Clang's nearest is -Wshadow-uncaptured-local.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wshadow=local)
  else()
    target_compile_options(${target} PRIVATE -Wshadow-uncaptured-local)
  endif()
  if(NADIR_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# nadir_set_warnings(<target>): the project's warning flags on one target.
function(nadir_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow=local)
  if(NADIR_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

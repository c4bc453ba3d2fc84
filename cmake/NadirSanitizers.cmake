# NADIR_SANITIZE: every target built with AddressSanitizer and
# UndefinedBehaviorSanitizer (any undefined behaviour stops the program).
# NADIR_FUZZ: also the coverage libFuzzer needs, and the targets in fuzz/;
# Clang only. Both belong in a build directory of their own (docs/reliability.md).
if(NADIR_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "NADIR_FUZZ needs Clang's libFuzzer: configure a new build directory "
                        "with CC=clang CXX=clang++ (scripts/fuzz.sh does)")
  endif()
  set(NADIR_SANITIZE ON CACHE BOOL "Build with AddressSanitizer and UndefinedBehaviorSanitizer" FORCE)
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

if(NADIR_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=undefined
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()

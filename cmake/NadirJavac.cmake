# Compiles every .java file below SOURCES into CLASSES against CLASSPATH (run
# with cmake -P: lcm-gen's file names are known only once it has run).
file(GLOB_RECURSE sources ${SOURCES}/*.java)
if(NOT sources)
  message(FATAL_ERROR "no Java sources in ${SOURCES}")
endif()
execute_process(
  COMMAND ${JAVAC} -nowarn -encoding UTF-8 -cp ${CLASSPATH} -d ${CLASSES} ${sources}
  RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "javac failed (${result})")
endif()

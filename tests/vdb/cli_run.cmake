# For the `flurry run --vdb` script tests: runs FLURRY with `run EFFECT --vdb FOLDER --quiet`
# and the extra arguments, and fails unless FOLDER then holds exactly EXPECTED (a sorted
# list of file names). The tool's output is left in `out` in the caller's scope.
function(expect_vdb_files effect folder expected)
  execute_process(COMMAND ${FLURRY} run ${effect} --vdb ${folder} --quiet ${ARGN}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "flurry run ${effect} --vdb ${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  file(GLOB files RELATIVE ${folder} ${folder}/*)
  list(SORT files)
  if(NOT files STREQUAL "${expected}")
    message(FATAL_ERROR "${effect} ${ARGN}: wrote '${files}', expected '${expected}':\n${out}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

# `flurry run --vdb` writes at the cadence of every other output: --every's N (default 10) and
# the last frame, unless --vdb-every says otherwise.
#   -DFLURRY=<tool> -DDIR=<scratch folder>
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE ${DIR})

function(expect_files folder expected)
  execute_process(COMMAND ${FLURRY} run fountain --frames 12 --vdb ${folder} --vdb-fog
                          --voxel-size 0.05 --quiet ${ARGN}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "flurry run fountain --vdb ${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  file(GLOB files RELATIVE ${folder} ${folder}/*)
  list(SORT files)
  if(NOT files STREQUAL "${expected}")
    message(FATAL_ERROR "--vdb ${ARGN}: wrote '${files}', expected '${expected}'")
  endif()
endfunction()

expect_files(${DIR}/default "fountain.0010.vdb;fountain.0012.vdb")
expect_files(${DIR}/every4 "fountain.0004.vdb;fountain.0008.vdb;fountain.0012.vdb" --every 4)
expect_files(${DIR}/vdb5 "fountain.0005.vdb;fountain.0010.vdb;fountain.0012.vdb" --every 4
             --vdb-every 5)

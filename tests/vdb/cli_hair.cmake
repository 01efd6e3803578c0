# `flurry run --vdb` on hair: an effect of hair alone is static, so a frame is written only
# when strands were added since the file before it (not one identical file per frame); the
# strands are also written as the `strands` point grid, read back by vdb_print when given.
#   -DFLURRY=<tool> -DDIR=<scratch folder> -DSRC=<source tree> [-DVDB_PRINT=<vdb_print>]
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE ${DIR})

include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)
function(run_hair effect folder expected)
  expect_vdb_files(${effect} ${folder} "${expected}" --frames 6 --vdb-every 1 --voxel-size 0.05)
  set(out "${out}" PARENT_SCOPE)
endfunction()

# The built-in hair: one burst at t = 0, so frame 1 holds every strand and 2..6 repeat it.
run_hair(hair ${DIR}/static "hair.0001.vdb")
if(NOT out MATCHES "vdb: hair is static: 5 later frames, unchanged since the last file, not written")
  message(FATAL_ERROR "no line about the frames left out:\n${out}")
endif()
if(NOT out MATCHES "[0-9]+ strand vertices")
  message(FATAL_ERROR "no strand vertex count:\n${out}")
endif()

# Hair that grows: a second burst at t = 0.1 s (frame 3 at 30 steps a second) adds strands,
# so frame 3 is written too; the frames between are not.
file(READ ${SRC}/samples/effects/hair.json json)
string(JSON json SET "${json}" name "\"grow\"")
string(JSON json SET "${json}" groups 0 emitters 0 bursts
       "[{\"time\": 0, \"count\": 50}, {\"time\": 0.09, \"count\": 50}]")
file(WRITE ${DIR}/grow.json "${json}")
run_hair(${DIR}/grow.json ${DIR}/grow "grow.0001.vdb;grow.0003.vdb")

# An independent reader sees the strands as points.
if(VDB_PRINT)
  execute_process(COMMAND ${VDB_PRINT} -l ${DIR}/static/hair.0001.vdb
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "Name: strands\n[^N]*Type: Tree_ptdataidx32"
     OR NOT out MATCHES "strand_vertex_meaning")
    message(FATAL_ERROR "vdb_print does not show the `strands` point grid (${rc}):\n${out}\n${err}")
  endif()
endif()

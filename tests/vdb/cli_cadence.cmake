# `flurry run --vdb` writes at the cadence of every other output: --every's N (default 10) and
# the last frame, unless --vdb-every says otherwise.
#   -DFLURRY=<tool> -DDIR=<scratch folder>
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE ${DIR})

include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)
function(expect_files folder expected)
  expect_vdb_files(fountain ${folder} "${expected}" --frames 12 --vdb-fog --voxel-size 0.05 ${ARGN})
endfunction()

expect_files(${DIR}/default "fountain.0010.vdb;fountain.0012.vdb")
expect_files(${DIR}/every4 "fountain.0004.vdb;fountain.0008.vdb;fountain.0012.vdb" --every 4)
expect_files(${DIR}/vdb5 "fountain.0005.vdb;fountain.0010.vdb;fountain.0012.vdb" --every 4
             --vdb-every 5)

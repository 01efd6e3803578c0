# Runs the `flurry` tool headless (DISPLAY unset) and checks what it leaves behind.
#   MODE=png:   `run --png` writes PNG frames at the --every cadence.
#   MODE=nogl:  with no display and no Xvfb on PATH, `--png` fails with a clear message,
#               and the same run without it still simulates and writes PLY files.
#   MODE=view:  `view` refuses to open without a display, naming the reason; its --dt is
#               accepted and checked like run's.
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE ${DIR})

function(expect_png path)
  if(NOT EXISTS ${path})
    message(FATAL_ERROR "missing ${path}")
  endif()
  file(READ ${path} head LIMIT 8 HEX)
  if(NOT head STREQUAL "89504e470d0a1a0a")
    message(FATAL_ERROR "${path} is not a PNG (starts ${head})")
  endif()
endfunction()

if(MODE STREQUAL "png")
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${FLURRY} run fountain --frames 20 --every 10
            --png ${DIR} --size 320x180 --quiet
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "flurry run --png failed (${rc}):\n${out}\n${err}")
  endif()
  expect_png(${DIR}/fountain.0010.png)
  expect_png(${DIR}/fountain.0020.png)
  file(GLOB all ${DIR}/*)
  list(LENGTH all n)
  if(NOT n EQUAL 2)
    message(FATAL_ERROR "expected 2 files in ${DIR}, found: ${all}")
  endif()
  if(NOT out MATCHES "wrote 2 PNG frames")
    message(FATAL_ERROR "no summary line in:\n${out}")
  endif()
elseif(MODE STREQUAL "nogl")
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY PATH=/nonexistent ${FLURRY} run fountain
            --frames 5 --png ${DIR} --quiet
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "--png: no usable OpenGL: DISPLAY is not set; cannot start Xvfb")
    message(FATAL_ERROR "expected a clear --png failure, got (${rc}):\n${out}\n${err}")
  endif()
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY PATH=/nonexistent ${FLURRY} run fountain
            --frames 5 --every 5 --out ${DIR} --quiet
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${DIR}/fountain.0005.ply)
    message(FATAL_ERROR "simulation without --png should work (${rc}):\n${out}\n${err}")
  endif()
elseif(MODE STREQUAL "view")
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${FLURRY} view fountain --exit-after 2
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "view: no usable OpenGL: DISPLAY is not set")
    message(FATAL_ERROR "expected `view` to need a display, got (${rc}):\n${out}\n${err}")
  endif()
  # `--dt` (docs/rendering.md) is accepted, then the display is what is missing ...
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${FLURRY} view fountain --dt 0.02 --exit-after 2
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "view: no usable OpenGL: DISPLAY is not set")
    message(FATAL_ERROR "`view --dt 0.02` should parse, then need a display (${rc}):\n${out}\n${err}")
  endif()
  # ... and is checked like `run --dt`.
  foreach(bad 0 -1 11 x)
    execute_process(
      COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${FLURRY} view fountain --dt ${bad}
      RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(rc EQUAL 0 OR NOT err MATCHES "--dt" OR err MATCHES "OpenGL")
      message(FATAL_ERROR "`view --dt ${bad}` should be refused naming --dt (${rc}):\n${out}\n${err}")
    endif()
  endforeach()
else()
  message(FATAL_ERROR "MODE must be png, nogl or view")
endif()

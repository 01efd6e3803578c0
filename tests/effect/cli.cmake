# Runs the `flurry` tool and checks its exit code and output.
#   MODE=validate: good files print "ok" (exit 0); bad ones name the file, the JSON path and
#                  why (exit 1); warnings go to stderr; folders and endless files are refused.
#   MODE=run:      --quiet prints one summary line accounting for every particle; --out writes
#                  PLY files; a file path runs; what the system refuses (memory, threads) is
#                  one line and exit 1, never an abort.
#   MODE=list:     every effect file of samples/effects, with its description.
#   MODE=log:      stdout and stderr into one pipe are whole lines; FLURRY_PROGRESS=1 there
#                  prints a line per tenth of the run instead of a line per frame.
# SANITIZE: the sanitizer build (no address-space limits); RENDER: the tool has --png; VDB:
# the tool has --vdb.
cmake_minimum_required(VERSION 3.25)

function(flurry_expect)
  # LIMIT_KB: run under `ulimit -v` (an address-space limit, KiB).
  cmake_parse_arguments(E "" "RC;OUT;ERR;LIMIT_KB" "ARGS" ${ARGN})
  set(limit)
  if(E_LIMIT_KB)
    set(limit sh -c "ulimit -v ${E_LIMIT_KB} && exec \"$@\"" sh)
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env FLURRY_PROGRESS=0 ${limit} ${FLURRY} ${E_ARGS}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL E_RC)
    message(FATAL_ERROR "flurry ${E_ARGS}: exit ${rc}, expected ${E_RC}\n${out}\n${err}")
  endif()
  if(E_OUT AND NOT out MATCHES "${E_OUT}")
    message(FATAL_ERROR "flurry ${E_ARGS}: stdout does not match '${E_OUT}':\n${out}")
  endif()
  if(E_ERR AND NOT err MATCHES "${E_ERR}")
    message(FATAL_ERROR "flurry ${E_ARGS}: stderr does not match '${E_ERR}':\n${err}")
  endif()
  set(last_out "${out}" PARENT_SCOPE)
endfunction()

if(MODE STREQUAL "validate")
  flurry_expect(RC 0 OUT "fountain.json: ok" ARGS validate ${SRC}/samples/effects/fountain.json)
  flurry_expect(RC 0 OUT "snow: ok" ARGS validate snow)
  flurry_expect(RC 1
    ERR "bad_rate.json: groups\\[0\\]\\.emitters\\[2\\]\\.rate: must be finite and >= 0"
    ARGS validate ${SRC}/tests/effect/data/bad_rate.json)
  flurry_expect(RC 1
    ERR "typo.json: groups\\[0\\]\\.emiters: unknown field; did you mean \"emitters\"\\?"
    ARGS validate ${SRC}/tests/effect/data/typo.json)
  flurry_expect(RC 1 ERR "cannot open" ARGS validate ${DIR}/missing.json)
  # One bad file among good ones fails the whole call, and the good ones still say ok.
  flurry_expect(RC 1 OUT "fountain.json: ok" ERR "typo.json"
    ARGS validate ${SRC}/samples/effects/fountain.json ${SRC}/tests/effect/data/typo.json)
  # A folder says so; a file that never ends is read up to the size bound.
  flurry_expect(RC 1 ERR "flurry: [^\n]*/tests/effect/data: is a directory\n"
    ARGS validate ${SRC}/tests/effect/data)
  if(EXISTS /dev/zero)
    flurry_expect(RC 1 ERR "^flurry: /dev/zero: larger than 64 MiB, the limit for an effect file\n$"
      ARGS validate /dev/zero)
  endif()
  # Warnings: the file is still ok (exit 0); each warning is a line on stderr with its path.
  flurry_expect(RC 0 OUT "no_move.json: ok, 2 warnings"
    ERR "flurry: warning: [^\n]*no_move.json: groups\\[0\\]\\.actions: has no Move: particles never move or age\n[^\n]*groups\\[0\\]\\.actions\\[1\\]: never kills"
    ARGS validate ${SRC}/tests/effect/data/no_move.json)
  # A valid file whose parsed form does not fit in memory: one line naming it, not an abort.
  if(NOT SANITIZE)
    string(REPEAT "[]," 6000000 many)
    file(WRITE ${DIR}/big.json "{\"groups\": [{\"capacity\": 1}], \"$comment\": [${many}[]]}")
    flurry_expect(RC 1 ERR "^flurry: [^\n]*big.json: out of memory[^\n]*\n$" LIMIT_KB 400000
      ARGS validate ${DIR}/big.json)
    file(REMOVE ${DIR}/big.json)
  endif()
  # The render object is checked as `run --png` reads it, with the file's name.
  if(RENDER)
    flurry_expect(RC 1 ERR "bad_render.json: render\\.camera\\.ptich: unknown field"
      ARGS validate ${SRC}/tests/effect/data/bad_render.json)
  endif()
elseif(MODE STREQUAL "run")
  file(REMOVE_RECURSE ${DIR})
  flurry_expect(RC 0 OUT "^fountain: 5 steps in [0-9.]+ s; emitted [0-9]+ = alive [0-9]+ \\+ killed by age [0-9]+ \\+ absorbed [0-9]+ \\+ non-finite [0-9]+ \\+ dropped at capacity [0-9]+\n$" ARGS run fountain --frames 5 --quiet)
  string(REGEX MATCHALL "\n" lines "${last_out}")
  list(LENGTH lines n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "--quiet printed ${n} lines:\n${last_out}")
  endif()
  flurry_expect(RC 0 OUT "frame +4 .*live.*wrote 2 PLY files"
    ARGS run ${SRC}/samples/effects/magnetic.json --frames 4 --every 2 --out ${DIR} --seed 5 --dt 0.02 --threads 1)
  if(NOT EXISTS ${DIR}/ions.0002.ply OR NOT EXISTS ${DIR}/ions.0004.ply)
    message(FATAL_ERROR "missing PLY files in ${DIR}")
  endif()
  flurry_expect(RC 1 ERR "no built-in effect.*did you mean \"fountain\"" ARGS run fountian)
  flurry_expect(RC 1 ERR "bad_rate.json: groups\\[0\\]" ARGS run ${SRC}/tests/effect/data/bad_rate.json)
  # The run's defaults come from the file; the flags override them.
  flurry_expect(RC 0 OUT "hair: 30 steps" ARGS run hair --quiet)
  # Particles killed as non-finite are in the summary (every one of them, here).
  flurry_expect(RC 0
    OUT "nonfinite: 10 steps in [0-9.]+ s; emitted 300 = alive 0 \\+ killed by age 0 \\+ absorbed 0 \\+ non-finite 300 \\+ dropped at capacity 0"
    ARGS run ${SRC}/tests/effect/data/nonfinite.json --frames 10 --quiet)
  flurry_expect(RC 0 OUT "blowup: 10 steps.*non-finite 300"
    ARGS run ${SRC}/tests/effect/data/nonfinite.json --frames 10)
  # --spawn-scale: twice the births (Effect::scaleSpawning); none or a negative is refused.
  flurry_expect(RC 0 OUT "nonfinite: 10 steps in [0-9.]+ s; emitted 600 = "
    ARGS run ${SRC}/tests/effect/data/nonfinite.json --frames 10 --quiet --spawn-scale 2)
  flurry_expect(RC 105 ERR "--spawn-scale: Value 0 not in range"
    ARGS run fountain --frames 1 --spawn-scale 0)
  # A warning does not stop a run.
  flurry_expect(RC 0 OUT "no_move: 3 steps" ERR "flurry: warning: [^\n]*no_move.json: groups\\[0\\]\\.actions: has no Move"
    ARGS run ${SRC}/tests/effect/data/no_move.json --frames 3 --quiet)
  if(RENDER)
    flurry_expect(RC 1 ERR "bad_render.json: render\\.camera\\.ptich: unknown field"
      ARGS run ${SRC}/tests/effect/data/bad_render.json --frames 1)
  endif()
  # What the system refuses is one line and exit 1, not an abort (std::terminate).
  if(NOT SANITIZE)
    flurry_expect(RC 1 ERR "^flurry: cannot start 1000 threads [^\n]*\n$" LIMIT_KB 1500000
      ARGS run fountain --threads 1000 --frames 2 --quiet)
  endif()
elseif(MODE STREQUAL "list")
  flurry_expect(RC 0 OUT "fountain +a water fountain" ARGS list)
  # Every effect file of samples/effects, one line each: its name, then its "description"
  # as the file has it (stored once, with the effect; a new sample needs one).
  file(GLOB files ${SRC}/samples/effects/*.json)
  list(LENGTH files n)
  string(REGEX MATCHALL "\n" lines "${last_out}")
  list(LENGTH lines listed)
  if(NOT listed EQUAL n)
    message(FATAL_ERROR "`flurry list` printed ${listed} lines for ${n} effect files:\n${last_out}")
  endif()
  foreach(f IN LISTS files)
    file(READ ${f} json)
    string(JSON name GET "${json}" name)
    string(JSON description ERROR_VARIABLE none GET "${json}" description)
    if(none OR description STREQUAL "")
      message(FATAL_ERROR "${f} has no \"description\" for `flurry list`")
    endif()
    string(FIND "${last_out}" "\n${name} " at)
    if(at LESS 0 AND NOT last_out MATCHES "^${name} ")
      message(FATAL_ERROR "`flurry list` lacks ${name}:\n${last_out}")
    endif()
    string(REGEX MATCH "(^|\n)${name} +([^\n]*)" line "${last_out}")
    if(NOT CMAKE_MATCH_2 STREQUAL description)
      message(FATAL_ERROR "`flurry list`: ${name}: '${CMAKE_MATCH_2}', the file says '${description}'")
    endif()
  endforeach()
elseif(MODE STREQUAL "log")
  # A log: stdout and stderr into one pipe, as `bash scripts/demo.sh > log 2>&1` makes.
  file(REMOVE_RECURSE ${DIR})
  set(vdb)
  if(VDB)  # the export's progress lines are the stderr that meets the per-frame lines
    set(vdb --vdb ${DIR} --vdb-every 6 --voxel-size 0.2)
  endif()
  function(flurry_log progress var)
    execute_process(COMMAND ${CMAKE_COMMAND} -E env FLURRY_PROGRESS=${progress}
                            sh -c "exec \"$@\" 2>&1" sh ${FLURRY} run fountain --frames 60 ${vdb}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "flurry run fountain ${vdb}: exit ${rc}\n${out}")
    endif()
    # Whole lines only: each one starts as the tool starts its lines, none is cut by another.
    string(REPLACE ";" "," lines "${out}")  # a CMake list splits at ';'
    string(REGEX MATCHALL "[^\n]*\n" lines "${lines}")
    foreach(line IN LISTS lines)
      if(NOT line MATCHES "^(frame +[0-9]+  t=[^\n]*live|\\[[#.]+\\] +[0-9]+%  frame [0-9]+/60  [^\n]*ETA [0-9:]+\n$|vdb \\[[#.]+\\] [0-9]+/[0-9]+ files [^\n]*ETA [0-9]+ s\n$|vdb: (wrote|last file) |fountain: 60 steps)")
        message(FATAL_ERROR "FLURRY_PROGRESS=${progress}: a line that is not whole: '${line}' in\n${out}")
      endif()
    endforeach()
    set(${var} "${out}" PARENT_SCOPE)
  endfunction()
  # Per-frame lines (no bar): the export's progress lines fall between them.
  flurry_log(0 out)
  string(REGEX MATCHALL "(^|\n)frame +[0-9]+ " frames "${out}")
  list(LENGTH frames n)
  if(NOT n EQUAL 60)
    message(FATAL_ERROR "FLURRY_PROGRESS=0: ${n} per-frame lines, expected 60:\n${out}")
  endif()
  # The bar in a log: a whole line at each tenth of the run (however short it is), no
  # per-frame lines but the last frame's statistics, and the export draws no bar of its own
  # beside it, only for the files still being written once the steps are done.
  flurry_log(1 out)
  string(REGEX MATCHALL "\\] +[0-9]+%  frame [0-9]+/60 " bars "${out}")
  string(REGEX REPLACE "\\] +[0-9]+%  frame ([0-9]+)/60 " "\\1" bars "${bars}")
  if(NOT bars STREQUAL "6;12;18;24;30;36;42;48;54;60")
    message(FATAL_ERROR "FLURRY_PROGRESS=1: progress lines at frames '${bars}', expected one per tenth:\n${out}")
  endif()
  string(REGEX MATCHALL "(^|\n)frame +[0-9]+ " frames "${out}")
  list(LENGTH frames n)
  if(NOT n EQUAL 1 OR NOT out MATCHES "\nframe +60 ")
    message(FATAL_ERROR "FLURRY_PROGRESS=1: per-frame lines beside the bar:\n${out}")
  endif()
  string(FIND "${out}" "100%  frame 60/60" end)
  string(FIND "${out}" "vdb [" export)
  if(export GREATER_EQUAL 0 AND export LESS end)
    message(FATAL_ERROR "FLURRY_PROGRESS=1: the export drew its bar beside the tool's:\n${out}")
  endif()
else()
  message(FATAL_ERROR "unknown MODE ${MODE}")
endif()

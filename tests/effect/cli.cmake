# Runs the `flurry` tool and checks its exit code and output.
#   MODE=validate: good files print "ok" (exit 0); bad ones name the file, the JSON path and
#                  why (exit 1).
#   MODE=run:      --quiet prints one summary line; --out writes PLY files; a file path runs.
#   MODE=list:     every built-in effect with a description.
cmake_minimum_required(VERSION 3.25)

function(flurry_expect)
  cmake_parse_arguments(E "" "RC;OUT;ERR" "ARGS" ${ARGN})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env FLURRY_PROGRESS=0 ${FLURRY} ${E_ARGS}
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
elseif(MODE STREQUAL "run")
  file(REMOVE_RECURSE ${DIR})
  flurry_expect(RC 0 OUT "^fountain: 5 steps in [0-9.]+ s; emitted [0-9]+, alive [0-9]+" ARGS run fountain --frames 5 --quiet)
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
elseif(MODE STREQUAL "list")
  flurry_expect(RC 0 OUT "fountain +a water fountain" ARGS list)
  foreach(name fireworks snow hair tornado pinball2d magnetic)
    if(NOT last_out MATCHES "\n?${name} +[a-zA-Z0-9]")
      message(FATAL_ERROR "`flurry list` lacks ${name}:\n${last_out}")
    endif()
  endforeach()
else()
  message(FATAL_ERROR "unknown MODE ${MODE}")
endif()

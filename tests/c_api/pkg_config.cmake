# Builds SOURCE with `CC $(pkg-config --cflags --libs flurry)` against the installed PREFIX and
# runs it: the pkg-config file is found, is relocatable and names a working library.
set(ENV{PKG_CONFIG_PATH} "${PREFIX}/${LIBDIR}/pkgconfig")
execute_process(COMMAND ${PKG_CONFIG} --cflags --libs flurry OUTPUT_VARIABLE flags
                ERROR_VARIABLE err RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config --cflags --libs flurry failed: ${err}")
endif()
execute_process(COMMAND ${PKG_CONFIG} --variable=libdir flurry OUTPUT_VARIABLE libdir
                OUTPUT_STRIP_TRAILING_WHITESPACE)
file(REAL_PATH "${libdir}" libdir)
file(REAL_PATH "${PREFIX}/${LIBDIR}" want)
if(NOT libdir STREQUAL want)
  message(FATAL_ERROR "flurry.pc's libdir is ${libdir}, not ${want}")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
file(MAKE_DIRECTORY ${DIR})
execute_process(COMMAND ${CC} -std=c99 -Wall -Werror ${SOURCE} -o ${DIR}/consumer ${flags}
                        -Wl,-rpath,${libdir}
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "compiling ${SOURCE} with ${flags} failed:\n${err}")
endif()
execute_process(COMMAND ${DIR}/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the consumer failed (${rc}):\n${out}${err}")
endif()
message(STATUS "${out}")

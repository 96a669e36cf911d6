# Writes version.h naming the commit of the source tree as it is built, with
# "-dirty" for uncommitted changes to tracked files. Run at every build: a
# commit, checkout or edit after the last configure would otherwise leave
# the log naming another commit. configure_file rewrites the header only when
# its text changes, so an unchanged tree recompiles nothing.
# Called with -DSOURCE_DIR -DIN -DOUT -DPROJECT_VERSION -DCMAKE_BUILD_TYPE.
execute_process(COMMAND git -C "${SOURCE_DIR}" describe --always --dirty --abbrev=7
                        --match=rotorfit-no-such-tag
                OUTPUT_VARIABLE ROTORFIT_GIT_HASH OUTPUT_STRIP_TRAILING_WHITESPACE
                ERROR_QUIET)
if(NOT ROTORFIT_GIT_HASH)
  set(ROTORFIT_GIT_HASH "unknown")
endif()
configure_file("${IN}" "${OUT}" @ONLY)

# Fails the build when docs/config-keys.md differs from what the key declarations give.
# cmake -DHAIRGEN=... -DDOC=... -DSTAMP=... -P check_config_keys.cmake
execute_process(COMMAND ${HAIRGEN} check --keys OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "hairgen check --keys failed (${rc})")
endif()
file(READ ${DOC} committed)
if(NOT generated STREQUAL committed)
  message(FATAL_ERROR "docs/config-keys.md is stale: run scripts/config-keys.sh, look at the diff and commit it")
endif()
file(TOUCH ${STAMP})

# SPDX-License-Identifier: Apache-2.0
# The ao command's man pages (ao.1, ao-SUBCOMMAND.1; Debian's help2man) and bash and zsh
# completion, generated from the built binary's --help at build time by scripts/cli-docs into
# build/cli-docs/, and installed (share/man/man1, share/bash-completion/completions/ao,
# share/zsh/vendor-completions/_ao).
find_program(AO_HELP2MAN help2man)
if(NOT AO_HELP2MAN)
  message(WARNING "help2man not found (scripts/setup installs it): ao's man pages are not generated")
endif()
set(AO_CLI_DOCS ${PROJECT_BINARY_DIR}/cli-docs)
add_custom_command(OUTPUT ${AO_CLI_DOCS}/stamp
                   COMMAND ${CMAKE_COMMAND} -E rm -rf ${AO_CLI_DOCS}/man1
                   COMMAND ${PROJECT_SOURCE_DIR}/scripts/cli-docs $<TARGET_FILE:ao> ${AO_CLI_DOCS} ${PROJECT_VERSION}
                   COMMAND ${CMAKE_COMMAND} -E touch ${AO_CLI_DOCS}/stamp
                   DEPENDS ao ${PROJECT_SOURCE_DIR}/scripts/cli-docs VERBATIM)
add_custom_target(ao_cli_docs ALL DEPENDS ${AO_CLI_DOCS}/stamp)
if(AO_INSTALL)
  include(GNUInstallDirs)
  install(DIRECTORY ${AO_CLI_DOCS}/man1 DESTINATION ${CMAKE_INSTALL_MANDIR})
  install(FILES ${AO_CLI_DOCS}/bash-completion/ao DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
  install(FILES ${AO_CLI_DOCS}/zsh-completion/_ao DESTINATION ${CMAKE_INSTALL_DATADIR}/zsh/vendor-completions)
endif()

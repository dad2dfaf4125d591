// SPDX-License-Identifier: Apache-2.0
// libFuzzer harness over ao's command line: each input is a command line, one argument per line
// ("render\n--width\n64"), parsed by the same CLI11 app as ao (cli/app.h). A parse error is reported
// as ao reports it (one line, closest names: parse_errors.h), and a command line that parses is turned
// into its job's request (values, parameter overrides and files, the camera, the falloff, the sun,
// the bakers' names) with GlobalOptions::request_only, so nothing is read beyond -p @FILE and nothing
// runs or is written. InputError is the expected answer to a bad value; a crash, a sanitizer
// report, a timeout or any other exception is a finding. Built by scripts/fuzz (AO_FUZZ_OPTIONS).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "ao/core/error.h"
#include "app.h"
#include "parse_errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args{"ao", ""};
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') args.emplace_back();
    else args.back() += static_cast<char>(data[i]);
  }
  if (args.size() > 64) return -1;  // longer command lines add nothing a shorter one does not test
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  const int argc = static_cast<int>(argv.size());

  CLI::App app("ao (fuzzed)", "ao");
  ao::cli::GlobalOptions global;
  global.request_only = true;
  std::function<int()> action;
  ao::cli::add_ao_commands(app, global, action);
  try {
    app.parse(argc, argv.data());
  } catch (const CLI::ParseError& e) {
    const int code = ao::cli::report_parse_error(app, e, argc, argv.data());
    if (code < 0 || code > 2) __builtin_trap();  // a parse error is 0 (--help, --version), 1 or 2
    return 0;
  }
  try {
    if (action) action();
  } catch (const ao::InputError&) {
  }
  return 0;
}

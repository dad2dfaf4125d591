// SPDX-License-Identifier: Apache-2.0
#include "parse_errors.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <CLI/CLI.hpp>

#include "ao/core/closest_name.h"

namespace ao::cli {

namespace {

std::vector<std::string> command_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(sub->get_name());
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// Every "--long" and "-s" name of `app`'s options.
std::vector<std::string> option_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : o->get_snames()) names.push_back("-" + s);
  }
  return names;
}

// The command that was being parsed: the subcommand named on the line, or null.
const CLI::App* chosen_command(const CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
      if (sub->get_name() == argv[i]) return sub;
  return nullptr;
}

// The first argument that is neither an option nor the value of --threads (the only global option
// that takes one): where a command should be.
std::string first_word(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads") {
      ++i;
      continue;
    }
    if (!a.empty() && a[0] != '-') return a;
  }
  return "";
}

// "The following arguments were not expected: a --b" -> {"a", "--b"}.
std::vector<std::string> unexpected_arguments(const std::string& message) {
  std::vector<std::string> words;
  const auto colon = message.find(": ");
  if (colon == std::string::npos) return words;
  std::istringstream in(message.substr(colon + 2));
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The option a conversion or validation message is about, and the value given to it on the line.
std::string bad_value_message(const CLI::App* cmd, const CLI::App& app, const std::string& what, int argc, char** argv) {
  for (const CLI::App* scope : {cmd, &app}) {
    if (scope == nullptr) continue;
    for (const CLI::Option* o : scope->get_options()) {
      for (const std::string& l : o->get_lnames()) {
        const std::string name = "--" + l;
        if (what.find(name) == std::string::npos) continue;
        std::string value;
        for (int i = 1; i + 1 < argc; ++i)
          if (name == argv[i]) value = argv[i + 1];
        const std::string type = o->get_type_name();
        const bool unsigned_whole = type.rfind("UINT", 0) == 0, whole = unsigned_whole || type.rfind("INT", 0) == 0;
        const bool number = whole || type.rfind("FLOAT", 0) == 0;
        std::string kind = unsigned_whole ? "a whole number >= 0" : whole ? "a whole number" : number ? "a number" : "a value of type " + type;
        if (!value.empty() && number) {
          char* end = nullptr;
          std::strtod(value.c_str(), &end);
          if (end == value.c_str() || *end != 0 || (whole && value.find_first_of(".eE") != std::string::npos) ||
              (unsigned_whole && value[0] == '-'))
            return name + ": expected " + kind + ", got '" + value + "'";
        }
        // In range of the type but refused by a check: CLI11's reason, after the option's name.
        std::string reason = what;
        if (reason.rfind(name + ": ", 0) == 0) reason = reason.substr(name.size() + 2);
        if (!reason.empty()) reason[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(reason[0])));
        return name + ": " + (value.empty() ? "" : "'" + value + "': ") + reason;
      }
    }
  }
  return what;
}

// What a value of `o` is, in words: "a whole number", "a number", or its type name ("KEY=VALUE").
std::string expected_value(const CLI::Option& o) {
  const std::string type = o.get_type_name();
  if (type.rfind("UINT", 0) == 0) return "a whole number >= 0";
  if (type.rfind("INT", 0) == 0) return "a whole number";
  if (type.rfind("FLOAT", 0) == 0) return "a number";
  if (type.empty() || type.rfind("TEXT", 0) == 0) return "a value";
  return type;
}

// An option given without its value (`ao render -p`): which option, and what it expects.
std::string missing_value_message(const CLI::App* cmd, const CLI::App& app, const std::string& what) {
  const CLI::Option* found = nullptr;
  std::string found_name;
  for (const CLI::App* scope : {cmd, &app}) {
    if (scope == nullptr) continue;
    for (const CLI::Option* o : scope->get_options())
      for (const std::string& l : o->get_lnames())
        if (what.find("--" + l) != std::string::npos && l.size() + 2 > found_name.size()) found = o, found_name = "--" + l;
  }
  if (found == nullptr) return what;
  return found_name + " needs a value: " + expected_value(*found);
}

// An option `cmd` does not take: the closest of its own, or the commands that take it (`ao bake -p`:
// bake's settings are options of their own). Single letters are all one edit apart, so a
// single-letter option gets no suggestion.
std::string unknown_option_message(const CLI::App& app, const CLI::App& cmd, const std::string& name, const std::string& help) {
  std::vector<std::string> known = option_names(cmd);
  for (const std::string& n : option_names(app)) known.push_back(n);
  const bool single_letter = name.size() == 2 && name[0] == '-';
  const std::string near = single_letter ? "" : closest_name(name, known);
  if (!near.empty()) return "unknown option '" + name + "'; did you mean '" + near + "'?";
  std::vector<std::string> takers;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    const std::vector<std::string> names = option_names(*sub);
    if (sub != &cmd && std::find(names.begin(), names.end(), name) != names.end()) takers.push_back(sub->get_name());
  }
  if (takers.empty()) return "unknown option '" + name + "'" + help;
  return "unknown option '" + name + "': an option of " + joined(takers) + ", not of " + cmd.get_name() + help;
}

}  // namespace

int report_parse_error(CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  const int code = e.get_exit_code();
  if (code == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
  const CLI::App* cmd = chosen_command(app, argc, argv);
  const std::string where = cmd ? cmd->get_name() + ": " : "";
  const std::string help = cmd ? " (ao " + cmd->get_name() + " --help lists the options)" : " (ao --help lists the commands)";
  const std::string what = e.what();
  if (code == static_cast<int>(CLI::ExitCodes::ConversionError) || code == static_cast<int>(CLI::ExitCodes::ValidationError)) {
    std::fprintf(stderr, "ao: error: %s%s\n", where.c_str(), bad_value_message(cmd, app, what, argc, argv).c_str());
    return 1;
  }
  if (cmd == nullptr) {
    const std::vector<std::string> commands = command_names(app);
    const std::string word = first_word(argc, argv);
    if (word.empty()) {
      std::fprintf(stderr, "ao: error: name a command: %s%s\n", joined(commands).c_str(), help.c_str());
    } else {
      const std::string near = closest_name(word, commands);
      std::fprintf(stderr, "ao: error: unknown command '%s'%s (commands: %s)\n", word.c_str(),
                   near.empty() ? "" : ("; did you mean '" + near + "'?").c_str(), joined(commands).c_str());
    }
    return 2;
  }
  if (code == static_cast<int>(CLI::ExitCodes::ExtrasError)) {
    for (const std::string& arg : unexpected_arguments(what)) {
      if (arg.empty() || arg[0] != '-') {
        std::fprintf(stderr, "ao: error: %sunexpected argument '%s'%s\n", where.c_str(), arg.c_str(), help.c_str());
        return 2;
      }
      const std::string message = unknown_option_message(app, *cmd, arg.substr(0, arg.find('=')), help);
      std::fprintf(stderr, "ao: error: %s%s\n", where.c_str(), message.c_str());
      return 2;
    }
  }
  if (code == static_cast<int>(CLI::ExitCodes::ArgumentMismatch)) {
    std::fprintf(stderr, "ao: error: %s%s%s\n", where.c_str(), missing_value_message(cmd, app, what).c_str(), help.c_str());
    return 2;
  }
  std::fprintf(stderr, "ao: error: %s%s%s\n", where.c_str(), what.c_str(), help.c_str());
  return 2;
}

}  // namespace ao::cli

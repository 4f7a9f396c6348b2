// Subcommands register themselves from their own cmd_*.cpp file, so adding a command touches
// no shared file. main.cpp builds the CLI11 app from the registry.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace hexfem {

struct CommandSpec {
  std::string name;
  std::string description;
  // Adds options to `sub` and returns the action to run when the subcommand is chosen.
  // The action returns the process exit code; it throws hexfem::Error on bad input.
  std::function<std::function<int()>(CLI::App& sub)> setup;
};

std::vector<CommandSpec>& command_registry();

// For an output path option: "" is refused (it read as "no output": nothing written, exit 0).
inline const CLI::Validator kNonEmptyPath(
    [](std::string& s) { return s.empty() ? std::string("the path is empty") : std::string(); }, "",
    "non-empty path");

struct RegisterCommand {
  explicit RegisterCommand(CommandSpec spec) { command_registry().push_back(std::move(spec)); }
};

}  // namespace hexfem

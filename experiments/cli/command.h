// Subcommands of the `pldvo` executable. Each lives in its own `*_command.cc`, defines its
// gflags there and registers itself with PLDVO_REGISTER_COMMAND; `pldvo CMD --help` lists the
// flags defined in that file.
#ifndef PLDVO_EXPERIMENTS_CLI_COMMAND_H_
#define PLDVO_EXPERIMENTS_CLI_COMMAND_H_

#include <string>
#include <vector>

namespace pldvo {

struct CommandContext {
  // Every `--set key=value` given, in order (repeatable; gflags keeps only the last value of a
  // flag, so the dispatcher collects these before gflags parses the rest).
  std::vector<std::string> config_overrides;
};

struct Command {
  std::string name;
  std::string summary;
  std::string source_file;  // __FILE__ of the command, to list its flags in --help
  int (*run)(const CommandContext& context);
  // Names of the flags from common_flags.h this command takes.
  std::vector<std::string> shared_flags;
};

// Registers a command at static-initialisation time; returns true.
bool RegisterCommand(const Command& command);
const std::vector<Command>& RegisteredCommands();

}  // namespace pldvo

// PLDVO_REGISTER_COMMAND("run", "summary", RunCommand, "dataset", "out"): the trailing names
// are the shared flags (common_flags.h) the command takes.
#define PLDVO_REGISTER_COMMAND(name, summary, function, ...) \
  static const bool kRegistered_##function =                 \
      ::pldvo::RegisterCommand({name, summary, __FILE__, &function, {__VA_ARGS__}})

#endif  // PLDVO_EXPERIMENTS_CLI_COMMAND_H_

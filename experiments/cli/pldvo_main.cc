// `pldvo SUBCOMMAND [flags]`: dispatches to the registered subcommands.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "experiments/cli/command.h"

namespace pldvo {

std::vector<Command>& MutableCommands() {
  static std::vector<Command> commands;
  return commands;
}

bool RegisterCommand(const Command& command) {
  MutableCommands().push_back(command);
  return true;
}

const std::vector<Command>& RegisteredCommands() { return MutableCommands(); }

namespace {

bool IsCommandFlag(const gflags::CommandLineFlagInfo& flag, const Command& command) {
  return flag.filename == command.source_file ||
         std::find(command.shared_flags.begin(), command.shared_flags.end(), flag.name) !=
             command.shared_flags.end();
}

void PrintUsage() {
  std::cout << "usage: pldvo SUBCOMMAND [flags]   (pldvo SUBCOMMAND --help lists its flags)\n\n"
               "subcommands:\n";
  std::vector<Command> commands = RegisteredCommands();
  std::sort(commands.begin(), commands.end(),
            [](const Command& a, const Command& b) { return a.name < b.name; });
  for (const Command& command : commands) {
    std::cout << "  " << command.name
              << std::string(10 - std::min<size_t>(9, command.name.size()), ' ') << command.summary
              << "\n";
  }
}

void PrintCommandHelp(const Command& command) {
  std::cout << "usage: pldvo " << command.name << " [flags]\n" << command.summary << "\n\nflags:\n";
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  for (const auto& flag : flags) {
    if (!IsCommandFlag(flag, command)) continue;
    std::cout << "  --" << flag.name << " (" << flag.type << ", default \"" << flag.default_value
              << "\")\n      " << flag.description << "\n";
  }
  std::cout << "  --set key=value (repeatable)\n      Overrides one config field, e.g. "
               "--set tracking.solver=gauss_newton.\n";
}

}  // namespace
}  // namespace pldvo

int main(int argc, char** argv) {
  using pldvo::Command;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    pldvo::PrintUsage();
    return argc < 2 ? 1 : 0;
  }
  const std::string name = argv[1];
  const auto& commands = pldvo::RegisteredCommands();
  const auto it = std::find_if(commands.begin(), commands.end(),
                               [&](const Command& c) { return c.name == name; });
  if (it == commands.end()) {
    std::cerr << "pldvo: unknown subcommand '" << name << "'\n";
    pldvo::PrintUsage();
    return 2;
  }
  // Collect the repeatable --set before gflags sees the arguments; catch --help here so that
  // only this subcommand's flags are listed.
  pldvo::CommandContext context;
  std::vector<char*> remaining = {argv[0]};
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h" || arg == "--helpfull") {
      pldvo::PrintCommandHelp(*it);
      return 0;
    } else if (arg == "--set" || arg == "-set") {
      if (i + 1 >= argc) {
        std::cerr << "pldvo " << name << ": --set needs key=value\n";
        return 2;
      }
      context.config_overrides.push_back(argv[++i]);
    } else if (arg.rfind("--set=", 0) == 0) {
      context.config_overrides.push_back(arg.substr(6));
    } else {
      remaining.push_back(argv[i]);
    }
  }
  int remaining_argc = static_cast<int>(remaining.size());
  char** remaining_argv = remaining.data();
  gflags::SetUsageMessage("pldvo " + name + ": " + it->summary);
  gflags::ParseCommandLineFlags(&remaining_argc, &remaining_argv, true);
  if (remaining_argc > 1) {
    std::cerr << "pldvo " << name << ": unexpected argument '" << remaining_argv[1] << "'\n";
    return 2;
  }
  // A flag of another subcommand is an error here, not silently ignored.
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  for (const auto& flag : flags) {
    if (!flag.is_default && !pldvo::IsCommandFlag(flag, *it) &&
        flag.filename.find("/experiments/") != std::string::npos) {
      std::cerr << "pldvo " << name << ": --" << flag.name << " is not a flag of this subcommand\n";
      return 2;
    }
  }
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  return it->run(context);
}

// Flags that several subcommands share. gflags names are global, so each is defined once (in
// common_flags.cc); a command lists the ones it takes in PLDVO_REGISTER_COMMAND, which makes
// them appear in its --help and be accepted on its command line.
#ifndef PLDVO_EXPERIMENTS_CLI_COMMON_FLAGS_H_
#define PLDVO_EXPERIMENTS_CLI_COMMON_FLAGS_H_

#include <gflags/gflags.h>

DECLARE_string(dataset);
DECLARE_string(format);
DECLARE_string(camera);
DECLARE_string(config);
DECLARE_string(out);
DECLARE_bool(json);

#endif  // PLDVO_EXPERIMENTS_CLI_COMMON_FLAGS_H_

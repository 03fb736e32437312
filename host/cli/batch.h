// batch.h - the `raster batch` subcommand's arguments (the runner is batch/batch_runner.h).
#ifndef RASTER_CLI_BATCH_H
#define RASTER_CLI_BATCH_H

#include "batch/batch_runner.h"

namespace CLI {
class App;
}

namespace sr {

// The `batch` subcommand and its options, filling `options`.
CLI::App* addBatchCommand(CLI::App& app, BatchOptions& options);

}  // namespace sr

#endif  // RASTER_CLI_BATCH_H

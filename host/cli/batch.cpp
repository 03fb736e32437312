// batch.cpp - the `raster batch` subcommand's arguments: its own options and every render setting as a
// default under the manifest's.
#include "cli/batch.h"

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/options.h"
#include "io/image_io.h"

namespace sr {

CLI::App* addBatchCommand(CLI::App& app, BatchOptions& o)
{
    CLI::App* batch = app.add_subcommand("batch", command("batch").summary);
    batch->add_option("manifest", o.manifest, "JSON Lines file: one job per line (docs/batch.md)")
        ->required();
    batch->add_option("--backend", o.backend, "auto (CUDA if present, else Vulkan), cuda or vulkan")
        ->check(CLI::IsMember({"auto", "cuda", "vulkan"}));
    batch->add_option("--devices", o.devices,
                      "devices to render on, one worker each: all, or indices such as 0,1 (default: the "
                      "backend's first device)");
    batch->add_option("--shard", o.shard,
                      "i/N: render the jobs whose index is i modulo N (default: the Slurm array task from "
                      "SLURM_ARRAY_TASK_ID, else every job)");
    batch
        ->add_option("--io-threads", o.ioThreads,
                     "threads encoding and writing files (default: every core not running a device's worker, "
                     "at least 1)")
        ->check(CLI::Range(1, 256));
    batch
        ->add_option("--queue", o.queueFrames,
                     "rendered frames waiting to be written (default: 2 per I/O thread)")
        ->check(CLI::Range(1, 4096));
    // Stored as the manifest's keys, under its header's and its jobs' values, checked with them.
    batch->add_option_function<std::string>(
        "--png-compression", [&o](const std::string& value) { o.defaults["png_compression"] = value; },
        pngCompressionHelp() + " (manifest key png_compression)");
    batch->add_option_function<std::string>(
        "--exr-compression", [&o](const std::string& value) { o.defaults["exr_compression"] = value; },
        exrCompressionHelp() + " (manifest key exr_compression)");
    batch->add_option("--summary", o.summaryPath, "write the JSON summary to this file too");
    batch->add_flag("--force", o.force, "render every job of the shard, even those already done");
    batch->add_flag("-q,--quiet", o.quiet, "no progress line and no summary on stdout");
    batch
        ->add_option("--io-delay-ms", o.ioDelayMs,
                     "testing: pause between a PNG's temporary file and its rename")
        ->group("");
    // Every render setting as a default under the manifest's header, stored by its manifest key.
    addSettingOptions(*batch, [&o](const Setting& setting, const nlohmann::json& value) {
        o.defaults[setting.key()] = value;
    });
    return batch;
}

}  // namespace sr

// `tessera bench --images DIR [--gt GT] MANIFEST...`: the arguments; the bench itself
// is in bench/.

#include <memory>

#include "bench/bench.h"
#include "cli/commands.h"
#include "cli/interrupt.h"

namespace tessera {

CommandRegistration RegisterBenchCommand(CLI::App& app, const GlobalOptions&) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand(
      "bench", "Run several manifests (and COLMAP) on the same images and compare them");
  sub->add_option("--images", options->images, "Folder of input images")->required();
  sub->add_option("--gt", options->ground_truth,
                  "Ground truth to score model 0 against (as for eval)");
  sub->add_option("--output", options->output, "Folder of the workspaces, one per manifest")
      ->default_val("bench-output");
  sub->add_option("--json", options->json_file, "Also write the rows as JSON to this file");
  sub->add_option("--csv", options->csv_file, "Also write the rows as CSV to this file");
  sub->add_option("--chart", options->chart_file,
                  "Also draw time per stage and position error per row as SVG (gnuplot)");
  sub->add_option("--camera-K", options->camera_K, "Known intrinsics for every manifest");
  sub->add_flag("--camera-per-folder", options->camera_per_folder,
                "One camera per subfolder of the images, in every run (and COLMAP's row)");
  sub->add_option("--threads", options->threads, "Worker threads of every run (default: all)")
      ->check(CLI::Range(0, 1024));
  sub->add_flag("--with-colmap", options->with_colmap,
                "Add COLMAP's rows (CPU, exhaustive): COLMAP 4's global and incremental "
                "mappers (TESSERA_COLMAP, else ../shared/anchors/colmap-4/bin/colmap) and "
                "COLMAP 3.8's (colmap on the PATH)");
  sub->add_option("--colmap", options->colmap_binaries,
                  "A COLMAP binary to run instead of those --with-colmap finds (repeat for "
                  "several; implies --with-colmap)")
      ->allow_extra_args(false);  // one path per --colmap: the manifests follow
  sub->add_flag("--colmap-mapper-only", options->colmap_mapper_only,
                "COLMAP's mappers alone, on a copy of the first manifest's database (the "
                "same matches), instead of COLMAP's whole pipeline (implies --with-colmap)");
  sub->add_option("--child-timeout", options->child_timeout,
                  "Seconds each row's process (a tessera run, each COLMAP step) may run before "
                  "it is stopped and its row says it timed out (default: 12 hours; COLMAP's -h: "
                  "60 s)")
      ->check(CLI::PositiveNumber);
  sub->add_option("MANIFEST", options->manifests, "Manifests to compare")->required();
  return {sub, [options]() {
            // Ctrl-C or SIGTERM stops the running row's processes; the rows that ran are
            // printed, and the bench ends with 130.
            const CancellationToken& interrupt = InterruptToken();
            options->stop_requested = [&interrupt] { return interrupt.IsCancelled(); };
            return RunBench(*options);
          }};
}

}  // namespace tessera

#include "common/program.hpp"

#include <omp.h>

#include <algorithm>
#include <charconv>
#include <new>

#include <CLI/CLI.hpp>
#include <fmt/ranges.h>
#include <cstdio>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "common/limits.hpp"
#include "common/progress.hpp"
#include "common/stop.hpp"
#include "common/version.hpp"

namespace outburst {

std::filesystem::path RunOptions::output_directory() const {
  if (!output.empty()) return output;
  return std::filesystem::path("results") / scene.stem();
}

bool RunOptions::show_progress() const { return !quiet && stderr_is_terminal(); }

OutputFolder::Earlier RunOptions::earlier_files() const {
  return restart ? OutputFolder::Earlier::restart
                 : overwrite ? OutputFolder::Earlier::overwrite : OutputFolder::Earlier::refuse;
}

output::RunInfo run_info(const std::string& program, const scene::Document& doc,
                         const std::string& units) {
  return {program,
          version,
          std::filesystem::absolute(doc.file()).string(),
          doc.text(),
          doc.overrides(),
          units};
}

SceneHeader read_scene_header(const scene::Table& root) {
  const auto s = root.table("scene", "what the scene is and which solvers it runs", true);
  SceneHeader h;
  h.title = s->string({"title", "a one-line description, copied into the outputs", "untitled"});
  h.solvers = s->choice_list(
      {"solvers", "the solvers this scene runs; nothing else is built", ""}, {"seepage", "mpm"});
  if (h.solvers.empty()) s->fail("solvers", "name at least one solver: [\"seepage\"], [\"mpm\"] or both");
  h.end_time = s->quantity({"end_time", "simulated time at which the run stops", "", scene::Range::positive()},
                           units::time);
  if (s->has("rest_fraction")) {
    if (std::find(h.solvers.begin(), h.solvers.end(), "mpm") == h.solvers.end())
      s->fail("rest_fraction", "the rest criterion watches the coal's kinetic energy: it needs the mpm solver");
    h.rest_fraction = s->number({"rest_fraction",
                                 "stop before end_time once the kinetic energy is below this fraction of its peak",
                                 "", {0.0, 1.0, false, false}});
  }
  const auto o = root.table("output", "what is written and how often", false);
  h.output_interval = h.end_time / 10;
  if (o && o->has("interval")) {
    h.output_interval = o->quantity({"interval", "simulated time between snapshots (default: end_time / 10)",
                                     "", scene::Range::positive()},
                                    units::time);
    limits::refuse_count(*o, "interval", h.end_time / h.output_interval, limits::max_snapshots, "snapshots",
                         fmt::format("end_time {:.3g} s / interval {:.3g} s, a file each; lengthen the interval",
                                     h.end_time, h.output_interval));
  }
  h.checkpoint_interval = h.output_interval;
  if (o) {
    // Read even when absent, so that --explain lists it with its default, in
    // the shortest form that reads back as the same number.
    const std::string every_snapshot = fmt::format("{} s", h.output_interval);
    h.checkpoint_interval = o->quantity({"checkpoint_interval",
                                         "simulated time between checkpoints (the run's whole state in "
                                         "checkpoint.h5), from which --restart continues a stopped run; a "
                                         "settling stage counts its own time (default: the output interval)",
                                         every_snapshot, scene::Range::positive()},
                                        units::time);
    // Each checkpoint rewrites one file, the run's whole state: not a count
    // of files, but of full writes.
    limits::refuse_count(*o, "checkpoint_interval", h.end_time / h.checkpoint_interval, limits::max_snapshots,
                         "checkpoints",
                         fmt::format("end_time {:.3g} s / checkpoint_interval {:.3g} s, the whole state each; "
                                     "lengthen the interval",
                                     h.end_time, h.checkpoint_interval));
  }
  return h;
}

void require_solvers(const scene::Table& root, const SceneHeader& header,
                     const std::vector<std::string>& supported, const std::string& program) {
  for (const auto& s : header.solvers)
    if (std::find(supported.begin(), supported.end(), s) == supported.end()) {
      const auto scene_table = root.table("scene", "", true);
      scene_table->fail("solvers", fmt::format("{} runs only {}; this scene also needs '{}'",
                                               program, fmt::join(supported, " and "), s));
    }
}

bool finish_reading(const RunOptions& options, const scene::Document& doc) {
  doc.reject_unused();
  if (options.explain) {
    std::fputs((options.explain_format == "json" ? doc.explain_json() : doc.explain()).c_str(), stdout);
    return false;
  }
  if (options.check_only) {
    spdlog::info("{}: the scene is valid", doc.file().string());
    return false;
  }
  return true;
}

namespace {

// More threads than this machine has cores only wait on each other, and
// thousands of them overflow the OpenMP runtime's stacks.
int most_threads() { return 4 * omp_get_num_procs(); }

CLI::Validator thread_count() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        int n = -1;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
        if (ec == std::errc() && end == text.data() + text.size() && n >= 0 && n <= most_threads()) return {};
        return fmt::format("{} is not a thread count for this machine: give 1 to {} (it has {} hardware threads), or "
                           "0 for one per hardware thread",
                           text, most_threads(), omp_get_num_procs());
      },
      fmt::format("INT in [0 - {}]", most_threads()));
}

}  // namespace

int run_program(const std::string& program, const std::string& description, int argc, char** argv,
                const std::function<int(const RunOptions&, scene::Document&)>& run) {
  CLI::App app(description, program);
  RunOptions options;
  app.add_option("scene", options.scene, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
  app.add_option("-o,--output", options.output, "Output folder (default: results/<scene name>)");
  app.add_option("-s,--set", options.overrides,
                 "Override a scene key: dotted.key=<TOML value>, e.g. "
                 "--set seepage.time_step='\"30 min\"'");
  app.add_flag("--check", options.check_only, "Validate the scene and stop");
  auto* overwrite = app.add_flag("--overwrite", options.overwrite,
                                 "Replace the files of an earlier run in the output folder (otherwise such a folder "
                                 "is refused)");
  app.add_flag("--restart", options.restart,
               "Continue the run in the output folder from its last checkpoint: give the scene, -o and --set of "
               "the stopped run (and the same -j for a bit-identical result)")
      ->excludes(overwrite);
  auto* explain = app.add_flag("--explain", options.explain,
                               "Print every key the scene uses with its value, default and meaning, and stop");
  app.add_option("--format", options.explain_format,
                 "What --explain prints: text, or json (each key also with what it expects, the words a choice "
                 "takes and its range)")
      ->check(CLI::IsMember({"text", "json"}))
      ->needs(explain);
  app.add_flag("-q,--quiet", options.quiet, "No progress line");
  app.add_option("--log-level", options.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  app.add_option("-j,--threads", options.threads, "OpenMP threads (default: all cores)")->check(thread_count());
  app.set_version_flag("--version", std::string(version));
  app.footer(fmt::format(
      "Exit codes: 0 done; 1 the run failed; 2 bad scene or command line; 3 stopped by SIGINT or SIGTERM; 4 scene "
      "refused as unworkable.\n\n"
      "Restart: a run writes its whole state to DIR/checkpoint.h5 every [output] checkpoint_interval of simulated "
      "time (default: with each snapshot) and when SIGINT or SIGTERM stops it. A run stopped so, killed or crashed "
      "continues from there with its own command line plus --restart, e.g.\n"
      "  {} SCENE -o DIR --set key=value --restart\n"
      "and ends as it would have without the stop, bit for bit. It refuses (exit code 2) a folder without a "
      "checkpoint, another scene text, mesh or --set, and another build.",
      program));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  auto logger = spdlog::stderr_color_mt(program);
  logger->set_pattern("[%H:%M:%S] [%n] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  install_stop_handlers();
  if (options.threads > 0) {
    omp_set_num_threads(options.threads);
  } else if (omp_get_max_threads() > most_threads()) {
    spdlog::warn("OMP_NUM_THREADS asks for {} threads; running {}, one per hardware thread", omp_get_max_threads(),
                 omp_get_num_procs());
    omp_set_num_threads(omp_get_num_procs());
  }

  try {
    auto doc = scene::Document::load(options.scene, options.overrides);
    return run(options, *doc);
  } catch (const scene::Refusal& e) {
    spdlog::error("{}", e.what());
    return 4;
  } catch (const scene::Error& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // The readers refuse sizes beyond the machine's memory, counting low; a
    // run can still outgrow what is free.
    spdlog::error("out of memory: the run needed more memory than was free (this machine has {:.3g} GB)",
                  limits::physical_memory() * 1e-9);
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}

}  // namespace outburst

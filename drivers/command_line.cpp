// kushner's command line: parse it, run the subcommand, turn what it throws into one line and an exit code.
#include "drivers/command_line.hpp"

#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "drivers/commands.hpp"
#include "drivers/config_file.hpp"
#include "engine/backend_session.hpp"
#include "engine/processes.hpp"
#include "engine/run_checkpointing.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <utility>

namespace kushner {
namespace {

/// `kushner compare` with no arguments: Sunahara's sine example, every filter that applies and the particle
/// reference, sized to finish within a minute on two CPU cores.
CompareOptions compare_defaults() {
  CompareOptions o;
  o.run.members = 200;
  o.run.dt = 2e-3;
  o.particles = 1024;
  return o;
}

struct Options {
  bool version = false;
  RunOptions simulate;
  FilterOptions filter;
  CompareOptions compare = compare_defaults();
  ReproduceOptions reproduce;
  ControlOptions control;
  bool controllers_json = false;
  bool models_json = false;
  bool filters_json = false;
  std::string resume_directory;
};

std::unique_ptr<CLI::App> make_app(Options& o) {
  auto app = std::make_unique<CLI::App>(
      "kushner: banks of nonlinear stochastic systems and filters, measured against the true conditional "
      "density.\nWhere it runs: KUSHNER_BACKEND=serial|openmp|cuda, OMP_NUM_THREADS.",
      "kushner");
  app->require_subcommand(0, 1);
  app->add_flag("--version", o.version, "print versions, the backend and its threads or device");
  add_run_options(*app->add_subcommand("simulate", "simulate the bank of truths and observations"), o.simulate);
  add_filter_options(*app->add_subcommand("filter", "run the bank of truths and filters side by side"), o.filter);
  add_compare_options(*app->add_subcommand("compare",
                                           "filters against the particle reference, with plots and a "
                                           "report (the main job; defaults: the sine model)"),
                      o.compare);
  add_reproduce_options(*app->add_subcommand("reproduce",
                                             "run a worked example of the seed papers and put the "
                                             "paper's numbers next to ours"),
                        o.reproduce);
  add_control_options(*app->add_subcommand("control",
                                           "controllers LAW@ESTIMATOR in closed loop on the bank, scored by "
                                           "their expected cost"),
                      o.control);
  app->add_subcommand("resume",
                      "continue a `filter` or `compare` run from the checkpoint in its output directory "
                      "(written every --checkpoint-every SECONDS, and on SIGINT or SIGTERM)")
      ->add_option("DIR", o.resume_directory, "the run's --out directory")
      ->required();
  app->add_subcommand("controllers", "list the control laws, estimators and aliases, and the models they control")
      ->add_flag("--json", o.controllers_json, "as JSON");
  app->add_subcommand("models", "list the built-in models and their parameters")
      ->add_flag("--json", o.models_json, "as JSON");
  app->add_subcommand("filters", "list the filters and the models each supports")
      ->add_flag("--json", o.filters_json, "as JSON");
  return app;
}

/// app.parse of `args` in their order (CLI11 consumes a reversed vector). Arguments no option takes are named in
/// the order they were given: CLI11 2.3's own message joins them backwards ("3 --bogus" for `--bogus 3`).
void parse_in_order(CLI::App& app, const std::vector<std::string>& args) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ExtrasError&) {
    const std::vector<std::string> extra = app.remaining(true);
    const auto subcommands = app.get_subcommands();
    std::string joined;
    for (const std::string& a : extra) joined += (joined.empty() ? "" : " ") + a;
    throw InputError((extra.size() == 1 ? "unexpected argument: " : "unexpected arguments: ") + joined + " (`kushner " +
                     (subcommands.empty() ? "" : subcommands[0]->get_name() + " ") + "--help` lists the options)");
  }
}

/// Parses argv; when the chosen subcommand has --config FILE, parses again with the file's options placed
/// before the command line's own (which therefore win). Returns nullptr after printing --help.
std::unique_ptr<CLI::App> parse(int argc, char** argv, Options& o) {
  std::vector<std::string> args(argv + 1, argv + argc);
  auto app = make_app(o);
  try {
    parse_in_order(*app, args);
  } catch (const CLI::Success& e) {  // --help: printed by the app that parsed it, for the right subcommand
    app->exit(e);
    return nullptr;
  }
  const auto subcommands = app->get_subcommands();
  if (subcommands.empty()) return app;
  const CLI::Option* config = subcommands[0]->get_option_no_throw("--config");  // `models` has none
  if (config == nullptr || config->count() == 0) return app;
  CLI::App* sub = subcommands[0];
  const std::string path = sub->get_option("--config")->as<std::string>();
  std::vector<std::string> expanded = config_file_arguments(path, *sub);
  const auto at = std::find(args.begin(), args.end(), sub->get_name());
  expanded.insert(expanded.begin(), args.begin(), at + 1);
  expanded.insert(expanded.end(), at + 1, args.end());
  o = Options{};
  app = make_app(o);
  parse_in_order(*app, expanded);
  return app;
}

int run(int argc, char** argv, const Checkpoint* resume = nullptr);

/// `kushner resume DIR`: the run of DIR's checkpoint again, with its arguments from its working directory,
/// continued from the checkpoint's state and writing into DIR.
int run_resume(const std::string& directory, char* program) {
  KUSHNER_INPUT_REQUIRE(collective::ranks() == 1,
                        "resume runs in one process: run it without mpirun (" << collective::ranks() << " ranks)");
  const std::filesystem::path out = std::filesystem::absolute(directory);
  const Checkpoint checkpoint = read_checkpoint(out);
  std::error_code ec;
  if (std::filesystem::is_directory(checkpoint.working_directory, ec))
    std::filesystem::current_path(checkpoint.working_directory);
  std::vector<std::string> arguments = checkpoint.arguments;
  arguments.insert(arguments.end(), {"--out", out.string()});  // the last --out wins: DIR, wherever it moved
  std::vector<char*> argv = {program};
  for (auto& a : arguments) argv.push_back(a.data());
  return run(static_cast<int>(argv.size()), argv.data(), &checkpoint);
}

/// `resume`: a run continued from a checkpoint (its argv is the checkpoint's arguments).
int run(int argc, char** argv, const Checkpoint* resume) {
  Options o;
  const std::unique_ptr<CLI::App> app = parse(argc, argv, o);
  if (!app) return 0;
  // A resumed run's outputs record the command that started it (without the --out that resume appends).
  RunContext context{command_line(resume ? argc - 2 : argc, argv), 0, "",
                     std::vector<std::string>(argv + 1, argv + (resume ? argc - 2 : argc))};
  if (app->got_subcommand("resume")) {
    KUSHNER_INPUT_REQUIRE(resume == nullptr, "a checkpoint's arguments cannot be `resume`");
    return run_resume(o.resume_directory, argv[0]);
  }
  KUSHNER_INPUT_REQUIRE(resume == nullptr || app->got_subcommand("filter") || app->got_subcommand("compare"),
                        "checkpoint: of a command other than filter or compare");
  if (o.version) return run_version();
  if (app->got_subcommand("models")) return run_models(o.models_json);
  if (app->got_subcommand("filters")) return run_filters_list(o.filters_json);
  if (app->got_subcommand("filter")) {
    context.seed = static_cast<std::uint32_t>(o.filter.run.seed);
    context.backend = selected_backend();
    return run_filter(o.filter, context, resume);
  }
  if (app->got_subcommand("compare")) {
    context.seed = static_cast<std::uint32_t>(o.compare.run.seed);
    context.backend = selected_backend();
    return run_compare(o.compare, context, resume);
  }
  if (app->got_subcommand("controllers")) return run_controllers_list(o.controllers_json);
  if (app->got_subcommand("control")) {
    context.seed = static_cast<std::uint32_t>(o.control.run.seed);
    context.backend = selected_backend();
    return run_control_command(o.control, context);
  }
  if (app->got_subcommand("reproduce")) {
    KUSHNER_INPUT_REQUIRE(collective::ranks() == 1,
                          "reproduce runs in one process: run it without mpirun (" << collective::ranks() << " ranks)");
    context.backend = selected_backend();
    return run_reproduce(o.reproduce, context);
  }
  if (app->got_subcommand("simulate")) {
    context.seed = static_cast<std::uint32_t>(o.simulate.seed);
    context.backend = selected_backend();
    return run_simulate(o.simulate, context);
  }
  std::cout << app->help();
  return 0;
}

/// `text` as one line: its first line, trailing blanks dropped (Kokkos' messages add lines such as
/// "Traceback functionality not available").
std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line;
}

/// Kokkos' allocation failure ("Kokkos failed to allocate memory for label "L".  Allocation using MemorySpace
/// named "S" failed ...:  Allocation of size 74.51 G failed, ...") as "L needs 74.51 G (S)".
std::string allocation_failure(const std::string& message) {
  auto between = [&message](const std::string& before, const std::string& after) -> std::string {
    const std::size_t begin = message.find(before);
    if (begin == std::string::npos) return "?";
    const std::size_t end = message.find(after, begin + before.size());
    return end == std::string::npos ? "?" : message.substr(begin + before.size(), end - begin - before.size());
  };
  return between("label \"", "\"") + " needs " + between("Allocation of size ", " failed") + " (memory space " +
         between("MemorySpace named \"", "\"") + ")";
}

/// The one line an error ends the run with, and its exit code.
std::pair<std::string, int> error_line() {
  try {
    throw;
  } catch (const RunInterrupted& e) {
    return {std::string("kushner: ") + e.what(), 128 + e.signal()};
  } catch (const CLI::ParseError& e) {
    return {std::string("kushner: error: ") + e.what(), 2};
  } catch (const InputError& e) {
    return {std::string("kushner: error: ") + e.what(), 2};
  } catch (const std::bad_alloc& e) {
    return {"kushner: error: not enough memory (" + first_line(e.what()) + "); reduce --members or --particles", 2};
  } catch (const std::exception& e) {
    const std::string message = first_line(e.what());
    if (message.rfind("Kokkos failed to allocate memory", 0) == 0)  // Kokkos rethrows bad_alloc as runtime_error
      return {"kushner: error: not enough memory: " + allocation_failure(message) + "; reduce --members or --particles",
              2};
    return {"kushner: internal error: " + message, 1};
  } catch (...) {
    return {"kushner: internal error: an exception of unknown type", 1};
  }
}

}  // namespace

int command_line_main(int argc, char** argv) {
  start_command_clock();
  // A file-size limit (ulimit -f) would kill the process with SIGXFSZ mid-write, leaving a .tmp file; ignored,
  // the write fails with EFBIG instead and OutputDirectory reports it like a full disk.
  std::signal(SIGXFSZ, SIG_IGN);
  ProcessGroup processes(argc, argv);
  const bool split = collective::ranks() > 1;
  // Every rank computes the same report; rank 0 alone prints it.
  if (split && collective::rank() != 0 && std::freopen("/dev/null", "w", stdout) == nullptr) return 1;
  try {
    return run(argc, argv);
  } catch (...) {
    const auto [line, code] = error_line();
    if (!split) {
      std::cerr << line << "\n";
      return code;
    }
    // Bad input fails on every rank alike: rank 0 says so and ends them all. Another rank waits a moment
    // first, so that it speaks only when it failed alone (e.g. its GPU ran out of memory) and rank 0 did not.
    if (collective::rank() != 0) std::this_thread::sleep_for(std::chrono::seconds(2));
    std::cerr << line << "\n" << std::flush;
    end_all_ranks(code);
  }
}

}  // namespace kushner

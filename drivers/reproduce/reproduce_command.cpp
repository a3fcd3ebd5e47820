// `kushner reproduce NAME --out DIR`: the seeds' worked examples run by the engine, with a table that puts the
// paper's numbers next to ours (drivers/reproduce/reproduction_table.hpp).
#include "core/errors.hpp"
#include "drivers/commands.hpp"
#include "drivers/csv.hpp"
#include "drivers/filter_command_impl.hpp"
#include "drivers/reproduce/reproduce_examples.hpp"
#include "drivers/reproduce/reproduce_options.hpp"
#include "engine/backend.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace kushner {

TerminalValues terminal_values(const OutputDirectory& out, long member) {
  std::ifstream in(out.path() / "trajectories.csv");
  KUSHNER_REQUIRE(in.good(), "terminal_values: no trajectories.csv in " << out.path().string());
  TerminalValues end;
  end.t = -1.0;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      KUSHNER_REQUIRE(line == "member,t,component,series,estimate,lower,upper", "trajectories.csv header " << line);
      header = false;
      continue;
    }
    std::istringstream fields(line);
    std::string m, t, component, series, estimate;
    std::getline(fields, m, ',');
    std::getline(fields, t, ',');
    std::getline(fields, component, ',');
    std::getline(fields, series, ',');
    std::getline(fields, estimate, ',');
    if (std::stol(m) != member) continue;
    const double time = std::stod(t);
    if (time > end.t) {
      end.t = time;
      end.series.clear();
    }
    if (time < end.t) continue;
    const int c = std::stoi(component);
    auto it = std::find_if(end.series.begin(), end.series.end(), [&](const auto& s) { return s.first == series; });
    if (it == end.series.end()) it = end.series.insert(end.series.end(), {series, {}});
    if (static_cast<int>(it->second.size()) <= c) it->second.resize(c + 1, std::nan(""));
    it->second[c] = std::stod(estimate);
  }
  KUSHNER_REQUIRE(end.t >= 0.0, "terminal_values: member " << member << " not in trajectories.csv");
  return end;
}

double TerminalValues::value(const std::string& name, int component) const {
  for (const auto& s : series)
    if (s.first == name && component < static_cast<int>(s.second.size())) return s.second[component];
  KUSHNER_REQUIRE(false, "terminal_values: no series " << name << " component " << component);
  return std::nan("");
}

namespace {

using ExampleFunction = ExampleResult (*)(const ReproduceSettings&, const RunContext&, const OutputDirectory&);

/// The examples and their default sizes. Deterministic examples (no randomness left: fixed truth, no process
/// noise, sin t as observation noise) run one member and take no --members, --particles, --seed.
struct Example {
  const char* name;
  ExampleFunction run;
  bool stochastic;
  double T, dt;
  long members;
  int particles;
};

const Example examples[] = {
    {"basin-car-filter", reproduce_basin_car_filter, false, 20.0, 2.5e-4, 1, 0},
    {"basin-terpolymer", reproduce_basin_terpolymer, false, 10.0, 1e-3, 1, 0},
    {"basin-car-regulator", reproduce_basin_car_regulator, false, 0.3, 5e-4, 1, 0},
    {"basin-regulator-enotes", reproduce_basin_regulator_enotes, false, 0.1, 5e-4, 1, 0},
    {"basin-car-controller", reproduce_basin_car_controller, true, 0.3, 2e-3, 1000, 0},
    {"sunahara-ex1", reproduce_sunahara_ex1, true, 10.0, 2e-3, 100, 1024},
    {"sunahara-ex2", reproduce_sunahara_ex2, true, 5.0, 2e-3, 100, 1024},
    {"clark-table-2.1", reproduce_clark_table_2_1, true, 100.0, 1.0, 500, 1024},
    {"clark-table-3.1", reproduce_clark_table_3_1, true, 100.0, 1.0, 500, 1024},
    {"clark-table-4.3", reproduce_clark_table_4_3, true, 100.0, 1.0, 1000, 0},
    {"tarushkin-attitude", reproduce_tarushkin_attitude, true, 10800.0, 10.0, 200, 0},
};

const Example& find_example(const std::string& name) {
  std::string known;
  for (const Example& e : examples) {
    if (name == e.name) return e;
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw InputError("reproduce: unknown example '" + name + "' (known: " + known + ")");
}

/// The example's sizes with the command line's overrides; InputError for anything the run cannot use.
ReproduceSettings resolve(const Example& e, const ReproduceOptions& o) {
  KUSHNER_INPUT_REQUIRE(!o.particles || e.particles > 0,
                        "--particles: " << e.name << " runs no particle filter; --members, --seed, --dt, --quiet and "
                                        << "--no-plots apply");
  if (!e.stochastic) {
    KUSHNER_INPUT_REQUIRE(!o.members && !o.particles && !o.seed,
                          (o.members     ? "--members"
                           : o.particles ? "--particles"
                                         : "--seed")
                              << ": " << e.name << " is deterministic (one run, no random numbers); only --dt, "
                              << "--quiet and --no-plots apply");
  }
  ReproduceSettings s;
  s.T = e.T;
  s.members = o.members.value_or(e.members);
  s.particles = o.particles.value_or(e.particles);
  s.seed = o.seed.value_or(1);
  s.dt = o.dt.value_or(e.dt);
  s.quiet = o.quiet;
  s.plots = o.plots;
  KUSHNER_INPUT_REQUIRE(
      s.members > 0 && s.members <= std::numeric_limits<std::int32_t>::max(),
      "--members: must be in 1 .. " << std::numeric_limits<std::int32_t>::max() << " (got " << s.members << ")");
  KUSHNER_INPUT_REQUIRE(!e.stochastic || e.particles == 0 || s.particles >= 1,
                        "--particles: must be at least 1 (got " << s.particles << ")");
  KUSHNER_INPUT_REQUIRE(s.seed >= 0 && s.seed <= 0xffffffffLL,
                        "--seed: must be in 0 .. 4294967295 (got " << s.seed << ")");
  KUSHNER_INPUT_REQUIRE(std::isfinite(s.dt) && s.dt > 0.0, "--dt: must be positive (got " << s.dt << ")");
  const double steps = e.T / s.dt;
  KUSHNER_INPUT_REQUIRE(time_grid_problem(e.T, s.dt) == TimeGridProblem::none,
                        "--dt: the horizon of " << e.name << ", T = " << e.T
                                                << ", must be a whole number of steps (T/dt = " << steps << ")");
  return s;
}

nlohmann::json rows_json(const ReproductionTable& table) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ReproductionRow& r : table.rows()) {
    nlohmann::json j = {{"key", r.paper.key},   {"quantity", r.paper.quantity}, {"paper", r.paper.paper},
                        {"verdict", r.verdict}, {"reading", r.reading},         {"source", r.paper.source},
                        {"why", r.why}};
    if (r.ours_text.empty()) {
      j["ours"] = r.ours;
      j["standard_error"] = r.standard_error;
    } else {
      j["ours"] = r.ours_text;
    }
    rows.push_back(j);
  }
  return rows;
}

/// report.md of an example with several runs: the table, then each run's figures and report.
std::string multi_run_report(const std::string& example, const nlohmann::json& summary, const std::string& table,
                             const std::vector<std::string>& runs) {
  const nlohmann::json& backend = summary["backend"];
  std::string report = "# kushner reproduce: " + example + "\n\n- command: `" + summary["command"].get<std::string>() +
                       "`\n- kushner " + summary["version"].get<std::string>() + " (git " +
                       summary.value("git", std::string("?")) + "), backend " +
                       backend.value("name", std::string("?")) + "\n\n" + table + "\n## Runs\n\n";
  for (const std::string& run : runs) {
    report += "### " + run + "\n\n[report](" + run + "/report.md)";
    for (const auto& file : summary["runs"][run]["files"]) {
      const std::string name = file.get<std::string>();
      if (name.size() > 4 && (name.compare(name.size() - 4, 4, ".csv") == 0 || name == "summary.json"))
        report += " · `" + run + "/" + name + "`";
    }
    report += "\n\n";
    for (const auto& file : summary["runs"][run]["files"]) {  // its figures: estimates, errors, ... or control_paths
      const std::string name = file.get<std::string>();
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".png") == 0)
        report += "![" + run + " " + name.substr(0, name.size() - 4) + "](" + run + "/" + name + ")\n\n";
    }
    if (summary["runs"][run].contains("plots_error")) {  // "no figures: ..." or "plotting failed: ..."
      std::string why = summary["runs"][run]["plots_error"].get<std::string>();
      why[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(why[0])));
      report += why + ".\n\n";
    }
  }
  return report;
}

}  // namespace

int run_reproduce(const ReproduceOptions& options, const RunContext& context_in) {
  const Example& example = find_example(options.example);
  const ReproduceSettings settings = resolve(example, options);
  RunContext context = context_in;
  context.seed = static_cast<std::uint32_t>(settings.seed);
  // A deterministic example is one member stepped tens of thousands of times: OpenMP's fork and join per kernel,
  // or a GPU's launch and copy latency per step, costs far more than the work (basin-car-filter: 18 s on one
  // thread, over 200 s on an H100). Unless KUSHNER_BACKEND asks otherwise, it runs on `serial` (the host on one
  // thread), which gives the same bits as more threads. So does an example without a particle filter
  // (basin-car-controller: 1000 members of dimension 2).
  const char* asked = std::getenv("KUSHNER_BACKEND");
  const std::vector<std::string> backends = available_backends();
  if ((!example.stochastic || example.particles == 0) && (asked == nullptr || *asked == '\0') &&
      context.backend != "serial" && std::find(backends.begin(), backends.end(), "serial") != backends.end())
    context.backend = "serial";
  const OutputDirectory out(options.out, "--out");
  KokkosSession kokkos(context.backend);
  ExampleResult result = example.run(settings, context, out);

  const std::string table_md = result.table.markdown(result.notes);
  out.write("reproduction.csv", result.table.csv(csv_comment(context)));
  out.write("reproduction.md", table_md);
  nlohmann::json& summary = result.summary;
  if (result.runs.empty()) {
    summary["reproduce"] = {{"example", example.name}, {"rows", rows_json(result.table)}};
    summary["files"].push_back("reproduction.csv");
    summary["files"].push_back("reproduction.md");
    if (settings.plots && !result.compare_report) {  // nothing for the compare figures to draw
      out.write("report.md", table_md);
      summary["files"].push_back("report.md");
      summary["plots"] = false;
    }
    out.write("summary.json", summary.dump(2) + "\n");
    if (settings.plots && result.compare_report) add_plots(out, summary);  // report.md includes reproduction.md
  } else {
    nlohmann::json top = run_metadata(context);
    top["reproduce"] = {{"example", example.name}, {"rows", rows_json(result.table)}};
    top["runs"] = summary["runs"];
    top["files"] = {"summary.json", "reproduction.csv", "reproduction.md"};
    if (settings.plots) {  // with each run's figures where they were drawn (not without matplotlib)
      out.write("report.md", multi_run_report(example.name, top, table_md, result.runs));
      top["files"].push_back("report.md");
    }
    out.write("summary.json", top.dump(2) + "\n");
    summary = top;
  }
  std::printf("kushner reproduce %s\n\n%s\n", example.name, result.table.text().c_str());
  if (summary.contains("plots_error"))
    std::fprintf(stderr, "kushner: warning: %s\n", summary["plots_error"].get<std::string>().c_str());
  for (const auto& run : result.runs)
    if (summary["runs"][run].contains("plots_error"))
      std::fprintf(stderr, "kushner: warning: %s: %s\n", run.c_str(),
                   summary["runs"][run]["plots_error"].get<std::string>().c_str());
  bool figures = settings.plots && summary.value("plots", true);
  for (const auto& run : result.runs) figures = figures && summary["runs"][run].value("plots", false);
  std::printf("written to %s/ (reproduction.csv, reproduction.md%s)\n", options.out.c_str(),
              figures          ? ", report.md, plots, CSV, JSON"
              : settings.plots ? ", report.md, CSV, JSON"
                               : ", CSV, JSON");
  return 0;
}

}  // namespace kushner

#include "drivers/plots.hpp"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <sys/wait.h>

#ifndef KUSHNER_SOURCE_DIR
#error "KUSHNER_SOURCE_DIR must name the source tree (it holds drivers/plots/compare_plots.py)"
#endif

namespace kushner {

namespace {

std::string shell_quote(const std::string& s) {
  std::string quoted = "'";
  for (char c : s) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string python_interpreter() {
  if (const char* p = std::getenv("KUSHNER_PYTHON"); p && *p) return p;
  if (std::filesystem::exists("/usr/bin/python3")) return "/usr/bin/python3";
  return "python3";
}

}  // namespace

PlotResult write_plots_and_report(const OutputDirectory& out) {
  return write_plots_and_report(out, "compare_plots.py", {"estimates", "errors", "rmse_ref", "density"});
}

PlotResult write_plots_and_report(const OutputDirectory& out, const std::string& script_name,
                                  const std::vector<std::string>& figures) {
  PlotResult result;
  if (!out.writes()) {  // another rank of an MPI run: rank 0 draws them
    result.message = "drawn by rank 0";
    return result;
  }
  const std::filesystem::path script = std::filesystem::path(KUSHNER_SOURCE_DIR) / "drivers/plots" / script_name;
  const std::string command = shell_quote(python_interpreter()) + " " + shell_quote(script.string()) + " " +
                              shell_quote(out.path().string()) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    result.message = "could not start " + python_interpreter();
    return result;
  }
  std::string output;
  std::array<char, 512> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int status = pclose(pipe);
  constexpr int report_without_figures = 3;  // compare_plots.py's exit status when matplotlib is missing
  const bool report_only = WIFEXITED(status) && WEXITSTATUS(status) == report_without_figures;
  if (status != 0) {
    while (!output.empty() && output.back() == '\n') output.pop_back();
    const auto last = output.rfind('\n');
    const std::string reason = last == std::string::npos ? output : output.substr(last + 1);
    result.message = (report_only ? "no figures: " : "plotting failed: ") + reason;
    if (report_only) result.files.push_back("report.md");
    return result;
  }
  result.ok = true;
  for (const std::string& name : figures)
    for (const char* ext : {".png", ".svg"})
      if (std::filesystem::exists(out.path() / (name + ext))) result.files.push_back(name + ext);
  result.files.push_back("report.md");
  return result;
}

}  // namespace kushner

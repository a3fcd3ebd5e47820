#pragma once
// Figures and report.md of a run directory, drawn by drivers/plots/compare_plots.py (matplotlib): the run
// itself writes only numbers, so a machine without Python still gets every CSV and JSON file.
#include "drivers/output_directory.hpp"

#include <string>
#include <vector>

namespace kushner {

struct PlotResult {
  bool ok = false;
  std::string message;             // why not, when !ok (one line)
  std::vector<std::string> files;  // what it wrote, when ok
};

/// Runs the plotting script on `out` (after summary.json and the CSV files are written). The interpreter is
/// $KUSHNER_PYTHON, else /usr/bin/python3 (Debian's, with python3-matplotlib), else python3 on PATH.
PlotResult write_plots_and_report(const OutputDirectory& out);

/// The same with another script of drivers/plots/ and the figures it may draw (NAME.png, NAME.svg).
PlotResult write_plots_and_report(const OutputDirectory& out, const std::string& script,
                                  const std::vector<std::string>& figures);

}  // namespace kushner

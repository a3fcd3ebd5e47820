// The paper-value tables of `kushner reproduce` (drivers/reproduce/*.csv): a table that parses can be filled and
// written, and its reproduction.csv reads back to the same keys, quantities, paper values and sources. The
// files are ours, so a malformed one is a KUSHNER_REQUIRE (std::logic_error), which passes here too.
#include "drivers/reproduce/reproduction_table.hpp"
#include "tests/fuzz/fuzz_check.hpp"
#include "tests/fuzz/fuzz_targets.hpp"

#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace kushner::fuzz {

int paper_values(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<PaperValue> values;
  try {
    values = parse_paper_values(text, "fuzz");
  } catch (const std::logic_error&) {
    return 0;
  }
  ReproductionTable table("fuzz", values);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const PaperValue& v = values[i];
    const double ours = static_cast<double>(i) - 1.5;  // some rows reproduce, some do not
    char* end = nullptr;
    const double paper = std::strtod(v.paper.c_str(), &end);
    const bool number = !v.paper.empty() && end == v.paper.c_str() + v.paper.size();
    if (number) {
      const double tolerance = reproduction_tolerance(v.paper, 0.25);
      FUZZ_CHECK(!(tolerance < 0.0), "a negative tolerance");
      table.add(v.key, ours, i % 2 ? 0.25 : 0.0, "reading, \"quoted\"");
      FUZZ_CHECK(table.verdict(v.key) == reproduces || table.verdict(v.key) == does_not_reproduce,
                 "a number without a verdict");
      (void)paper;
    } else if (i % 3 == 0) {
      table.add_none(v.key, "none", "reading");
    } else {
      table.add_text(v.key, "ours, in words", i % 2 == 0, "reading");
    }
    if (i % 4 == 1) table.explain(v.key, "why, with a \"quote\"");
  }
  (void)table.markdown("notes");
  (void)table.text();
  std::istringstream csv(table.csv("# comment\n"));
  std::string line;
  std::getline(csv, line);  // the comment
  std::getline(csv, line);  // the header
  for (const PaperValue& v : values) {
    FUZZ_CHECK(std::getline(csv, line), "reproduction.csv lacks a row");
    const std::vector<std::string> f = split_csv_line(line);
    FUZZ_CHECK(f.size() == 10, "a reproduction.csv row without its 10 fields");
    FUZZ_CHECK(f[1] == v.key && f[2] == v.quantity && f[3] == v.paper && f[8] == v.source,
               "a reproduction.csv row reads back to other values");
  }
  FUZZ_CHECK(!std::getline(csv, line), "reproduction.csv has rows the table has not");
  return 0;
}

}  // namespace kushner::fuzz

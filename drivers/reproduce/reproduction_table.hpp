#pragma once
// The table `kushner reproduce` writes: per number a paper prints (drivers/reproduce/<example>.csv, compiled
// into the binary), our value, its Monte Carlo standard error where there is one, a verdict and the reading of
// the paper that produced our value. Written as reproduction.csv, reproduction.md (also included in
// report.md) and printed on stdout.
#include <cmath>
#include <string>
#include <vector>

namespace kushner {

/// One row of an example's data file: `paper` as printed (its digits set the tolerance), empty where the paper
/// gives no number, or a short statement for a claim the paper makes in words.
struct PaperValue {
  std::string key, quantity, paper, source;
};

/// One line of CSV as fields; double quotes protect commas ("" is a quote).
std::vector<std::string> split_csv_line(const std::string& line);

/// The rows of a data file's text `csv` (a header key,quantity,paper,source; '#' lines and empty lines skipped;
/// double quotes protect commas; keys unique); KUSHNER_REQUIRE on a malformed one, naming `example`.
std::vector<PaperValue> parse_paper_values(const std::string& csv, const std::string& example);

/// The data file of `example` ("basin-car-filter", ...), parsed; InputError-free (the files are ours):
/// KUSHNER_REQUIRE on a malformed one.
std::vector<PaperValue> paper_values(const std::string& example);

/// The names of the examples that have a data file, sorted.
std::vector<std::string> paper_value_examples();

/// Verdicts.
inline constexpr const char* reproduces = "reproduces";
inline constexpr const char* does_not_reproduce = "does not reproduce";
inline constexpr const char* no_number = "no number in paper";

/// |ours - paper| may be as large as this and still reproduce: half a unit of the paper's last printed digit,
/// at least 1% of |paper|, plus three Monte Carlo standard errors of ours (0 for a deterministic value).
double reproduction_tolerance(const std::string& paper, double standard_error);

struct ReproductionRow {
  PaperValue paper;
  double ours = std::nan("");
  double standard_error = 0.0;  // 0: deterministic
  std::string ours_text;        // instead of `ours`, for counts and claims
  std::string verdict;
  std::string reading;  // which reading of the paper produced `ours`
  std::string why;      // why it does not reproduce, where we know (e.g. "impossible under the stated cost: ...")
};

class ReproductionTable {
 public:
  explicit ReproductionTable(std::string example);
  /// The table of rows `values` (the data file's, or a test's).
  ReproductionTable(std::string example, const std::vector<PaperValue>& values);

  /// Our number for the data file's row `key` (KUSHNER_REQUIRE that it exists and is not filled yet); the
  /// verdict follows from the paper's value and reproduction_tolerance.
  void add(const std::string& key, double ours, double standard_error, const std::string& reading);
  /// Our outcome in words for a row whose paper value is a claim (`holds`: whether ours agrees with it) or
  /// absent (`holds` ignored).
  void add_text(const std::string& key, const std::string& ours, bool holds, const std::string& reading);
  /// No number of ours for a row whose paper value is a number (our equations have no solution there, say):
  /// `ours` in words, the verdict `does not reproduce` (or `no number in paper`).
  void add_none(const std::string& key, const std::string& ours, const std::string& reading);
  /// Why row `key` (filled already) does not reproduce; shown after its verdict.
  void explain(const std::string& key, const std::string& why);
  /// The verdict of row `key` (filled already).
  const std::string& verdict(const std::string& key) const;

  /// KUSHNER_REQUIRE that every row of the data file has our value; rows in data-file order.
  const std::vector<ReproductionRow>& rows() const;
  const std::string& example() const { return example_; }

  /// reproduction.csv: example,key,quantity,paper,ours,standard_error,verdict,reading,source,why (numbers %.17g).
  std::string csv(const std::string& comment) const;
  /// reproduction.md: a heading, `notes` (markdown, what the example ran and which readings it used), the
  /// tolerance rule, and the table.
  std::string markdown(const std::string& notes) const;
  /// The table for a terminal: quantity, paper, ours, verdict.
  std::string text() const;

 private:
  ReproductionRow& row(const std::string& key);
  std::string example_;
  std::vector<ReproductionRow> rows_;
  std::vector<bool> filled_;
};

/// `value` with 4 significant digits, "± se" (2 digits) when se > 0; "-" for NaN.
std::string format_ours(double value, double standard_error, const char* plus_minus = "±");

}  // namespace kushner

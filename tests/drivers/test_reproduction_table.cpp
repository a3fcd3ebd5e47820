// The reproduction table of `kushner reproduce`: tolerances from the printed digits, verdicts, every data-file
// row filled, and the compiled-in data files parse with their paper values.
#include "drivers/reproduce/reproduction_table.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace kushner {
namespace {

TEST(ReproductionTable, ToleranceIsHalfTheLastPrintedDigitOrOnePercent) {
  EXPECT_DOUBLE_EQ(reproduction_tolerance("5", 0.0), 0.5);
  EXPECT_DOUBLE_EQ(reproduction_tolerance("0.905", 0.0), 0.01 * 0.905);  // 1% beats half of 0.001
  EXPECT_DOUBLE_EQ(reproduction_tolerance("0.48", 0.0), 0.005);
  EXPECT_DOUBLE_EQ(reproduction_tolerance("11.83", 0.0), 0.1183);
  EXPECT_DOUBLE_EQ(reproduction_tolerance("12.3", 0.1), 0.123 + 0.3);  // plus 3 standard errors
  EXPECT_THROW(reproduction_tolerance("BILIN best", 0.0), std::logic_error);
}

TEST(ReproductionTable, VerdictsFollowThePaperValue) {
  ReproductionTable table("basin-car-filter");
  table.add("tan/KB/m_phi", 7.341, 0.0, "r");    // paper 7.35: |d| = 0.009 < 0.0735
  table.add("tan/POLY3/m_phi", 7.42, 0.0, "r");  // paper 11.83
  EXPECT_THROW(table.add("tan/KB/m_phi", 7.0, 0.0, "twice"), std::logic_error);
  EXPECT_THROW(table.add("no/such/key", 1.0, 0.0, "r"), std::logic_error);
  EXPECT_THROW(table.rows(), std::logic_error) << "rows left without our value must be refused";
  for (const PaperValue& v : paper_values("basin-car-filter"))
    if (v.key != "tan/KB/m_phi" && v.key != "tan/POLY3/m_phi") table.add(v.key, 1.0, 0.0, "r");
  for (const ReproductionRow& r : table.rows()) {
    if (r.paper.key == "tan/KB/m_phi") {
      EXPECT_EQ(r.verdict, reproduces);
    }
    if (r.paper.key == "tan/POLY3/m_phi") {
      EXPECT_EQ(r.verdict, does_not_reproduce);
    }
    if (r.paper.key == "taylor/KB/delta") {
      EXPECT_EQ(r.verdict, reproduces) << "1 against a printed 1";
    }
    if (r.paper.key == "taylor/EXACT/m_phi") {
      EXPECT_EQ(r.verdict, no_number);
    }
  }
  EXPECT_NE(table.text().find("tan truth (18): KB m_phi(20)"), std::string::npos);
  EXPECT_NE(table.csv("# c\n").find("tan/KB/m_phi,tan truth (18): KB m_phi(20),7.35,7.3410000000000002,0,reproduces"),
            std::string::npos)
      << table.csv("");
}

TEST(ReproductionTable, EveryExampleHasItsDataFile) {
  const std::vector<std::string> examples = paper_value_examples();
  EXPECT_EQ(examples, (std::vector<std::string>{"basin-car-controller", "basin-car-filter", "basin-car-regulator",
                                                "basin-regulator-enotes", "basin-terpolymer", "clark-table-2.1",
                                                "clark-table-3.1", "clark-table-4.3", "sunahara-ex1", "sunahara-ex2",
                                                "tarushkin-attitude"}));
  const std::vector<PaperValue> car = paper_values("basin-car-filter");
  ASSERT_EQ(car.size(), 24u);
  EXPECT_EQ(car[2].key, "taylor/KB/m_phi");
  EXPECT_EQ(car[2].paper, "3.35");
  EXPECT_EQ(car[2].source, "002 L1513, table 1, row 3, column 1");
  int printed = 0;
  for (const auto& v : car) printed += !v.paper.empty();
  EXPECT_EQ(printed, 20) << "both tables: 2 systems x 2 columns x 4 rows, and the 4 rows of (21) as printed";
}

TEST(ReproductionTable, ClaimsTakeWordsAndGetAVerdict) {
  for (bool holds : {true, false}) {
    ReproductionTable table("basin-terpolymer");
    for (const PaperValue& v : paper_values("basin-terpolymer"))
      if (v.key != "claim/bilinear_best") table.add(v.key, 0.5, 0.0, "r");
    table.add_text("claim/bilinear_best", "BILIN 0.3, MIXED 0.4, KBL 0.9", holds, "r");
    EXPECT_EQ(table.rows().back().verdict, holds ? reproduces : does_not_reproduce);
    EXPECT_EQ(table.rows().front().verdict, no_number);
  }
  ReproductionTable table("basin-terpolymer");
  EXPECT_THROW(table.add("claim/bilinear_best", 1.0, 0.0, "r"), std::logic_error) << "a claim is not a number";
}

// A printed number without one of ours (no solution of our equations) does not reproduce; `explain` says why, in
// the verdict cell of the markdown, after the verdict on stdout and in the csv's `why` column.
TEST(ReproductionTable, RowsWithoutOurNumberAndWhy) {
  ReproductionTable table("basin-regulator-enotes");
  for (const PaperValue& v : paper_values("basin-regulator-enotes"))
    if (v.key.rfind("poly/eq11/", 0) == 0)
      table.add_none(v.key, "none", "r");
    else
      table.add(v.key, 0.6479, 0.0, "r");
  EXPECT_THROW(table.explain("no/such/key", "x"), std::logic_error);
  table.explain("poly/eq11/phi", "escapes to infinity");
  table.explain("poly/derived/J", "impossible under the stated cost");
  EXPECT_EQ(table.verdict("poly/eq11/phi"), does_not_reproduce);
  EXPECT_EQ(table.verdict("poly/derived/J"), does_not_reproduce);
  EXPECT_EQ(table.verdict("none/J"), no_number);
  EXPECT_NE(table.text().find("none                does not reproduce (escapes to infinity)"), std::string::npos)
      << table.text();
  EXPECT_NE(table.markdown("").find("| does not reproduce: impossible under the stated cost |"), std::string::npos);
  const std::string csv = table.csv("");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "example,key,quantity,paper,ours,standard_error,verdict,reading,source,why");
  EXPECT_NE(csv.find("poly/eq11/phi,"), std::string::npos);
  EXPECT_NE(csv.find(",none,0,does not reproduce,r,\"002 L1969, table, row 1, column 2\",escapes to infinity"),
            std::string::npos)
      << csv;
}

}  // namespace
}  // namespace kushner

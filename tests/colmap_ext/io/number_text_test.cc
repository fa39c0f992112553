#include "colmap_ext/io/number_text.h"

#include <gtest/gtest.h>

#include <limits>

namespace rig_calibrator {
namespace number_text_test {

TEST(NumberText, DoublesRoundTripBitForBit) {
  for (const double value : {312.41, 1e-5, -0.5, 0.1 + 0.2, 6.02214076e23,
                             std::numeric_limits<double>::denorm_min(),
                             std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::lowest(), 1.0 / 3}) {
    double parsed = 0;
    ASSERT_TRUE(ParseDouble(FormatDouble(value), &parsed)) << value;
    EXPECT_EQ(parsed, value);
  }
}

// The shortest text that reads back (not a fixed 17 digits): files stay
// readable and a hand-written 312.41 is written back as 312.41.
TEST(NumberText, DoublesAreWrittenAsTheShortestExactText) {
  EXPECT_EQ(FormatDouble(312.41), "312.41");
  EXPECT_EQ(FormatDouble(0.1), "0.1");
  EXPECT_EQ(FormatDouble(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(FormatDouble(500.0), "500");
  EXPECT_EQ(FormatDouble(-2.5e-7), "-2.5e-07");
}

TEST(NumberText, YamlFloatsAlwaysHaveADecimalPoint) {
  EXPECT_EQ(FormatYamlFloat(500.0), "500.0");
  EXPECT_EQ(FormatYamlFloat(1e-5), "1.0e-05");
  EXPECT_EQ(FormatYamlFloat(-0.25), "-0.25");
  EXPECT_EQ(FormatYamlFloat(-3.0), "-3.0");
  EXPECT_EQ(FormatYamlFloat(2e22), "2.0e+22");
  EXPECT_EQ(FormatYamlFloat(1.5e-7), "1.5e-07");
}

TEST(NumberText, ParseDoubleIsStrict) {
  double value = 7;
  EXPECT_TRUE(ParseDouble("+1.5", &value));
  EXPECT_EQ(value, 1.5);
  for (const char* bad :
       {"", "+", "+-1", "1.5x", " 1", "nan", "inf", "1e999"}) {
    value = 7;
    EXPECT_FALSE(ParseDouble(bad, &value)) << bad;
    EXPECT_EQ(value, 7) << bad;
  }
}

TEST(NumberText, ParseInt64IsStrict) {
  int64_t value = 7;
  EXPECT_TRUE(ParseInt64("+42", &value));
  EXPECT_EQ(value, 42);
  EXPECT_TRUE(ParseInt64("-9223372036854775808", &value));
  EXPECT_EQ(value, std::numeric_limits<int64_t>::min());
  for (const char* bad : {"", "1.0", "9223372036854775808", "+-3", "12a"}) {
    value = 7;
    EXPECT_FALSE(ParseInt64(bad, &value)) << bad;
    EXPECT_EQ(value, 7) << bad;
  }
}

}  // namespace number_text_test
}  // namespace rig_calibrator

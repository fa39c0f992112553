#include "colmap_ext/io/name_table.h"

#include <gtest/gtest.h>

namespace rig_calibrator {
namespace name_table_test {

enum class Color { kRed, kGreen, kBlue };

const NameTable<Color> kColors = {{Color::kRed, "red"},
                                  {Color::kGreen, "green"}};

TEST(NameTable, ReadsBothWays) {
  Color color = Color::kBlue;
  EXPECT_TRUE(ValueFromName(kColors, "green", &color));
  EXPECT_EQ(color, Color::kGreen);
  EXPECT_TRUE(ValueFromName(kColors, "red", &color));
  EXPECT_EQ(color, Color::kRed);
  EXPECT_EQ(NameOfValue(kColors, Color::kGreen, "?"), "green");
  EXPECT_EQ(NameOfValue(kColors, Color::kRed, "?"), "red");
}

TEST(NameTable, UnknownNamesAndValues) {
  Color color = Color::kBlue;
  EXPECT_FALSE(ValueFromName(kColors, "Green", &color));  // case matters
  EXPECT_FALSE(ValueFromName(kColors, "", &color));
  EXPECT_EQ(color, Color::kBlue);  // unchanged
  EXPECT_EQ(NameOfValue(kColors, Color::kBlue, "unknown"), "unknown");
}

}  // namespace name_table_test
}  // namespace rig_calibrator

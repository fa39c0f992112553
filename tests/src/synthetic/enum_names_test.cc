#include "src/synthetic/enum_names.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "src/synthetic/synthetic_rig.h"
#include "src/synthetic/textured_scene.h"

namespace rig_calibrator {
namespace enum_names_test {

enum class Color { kRed, kGreen, kBlue };
constexpr EnumNameTable<Color, 2> kColorNames = {
    {{Color::kRed, "red"}, {Color::kGreen, "green"}}};

TEST(EnumNames, ParsePrintAndList) {
  EXPECT_EQ(EnumName(kColorNames, Color::kGreen), "green");
  EXPECT_EQ(EnumName(kColorNames, Color::kBlue), "unknown");
  Color color = Color::kBlue;
  EXPECT_TRUE(EnumFromName(kColorNames, "red", &color));
  EXPECT_EQ(color, Color::kRed);
  EXPECT_TRUE(EnumFromName(kColorNames, "green", &color));
  EXPECT_EQ(color, Color::kGreen);
  // Unknown names and case differences leave the value alone.
  EXPECT_FALSE(EnumFromName(kColorNames, "Red", &color));
  EXPECT_FALSE(EnumFromName(kColorNames, "", &color));
  EXPECT_EQ(color, Color::kGreen);
  EXPECT_EQ(EnumValues(kColorNames),
            std::vector<Color>({Color::kRed, Color::kGreen}));
}

// Every value has a distinct name that parses back to it; the command-line
// names are these (a renamed preset breaks scripts).
template <typename Enum>
void ExpectNamesRoundTrip(const std::vector<Enum>& values,
                          std::string (*name_of)(Enum),
                          bool (*from_name)(const std::string&, Enum*),
                          const std::vector<std::string>& expected_names) {
  std::vector<std::string> names;
  for (const Enum value : values) {
    names.push_back(name_of(value));
    Enum parsed = values.back() == value ? values.front() : values.back();
    ASSERT_TRUE(from_name(names.back(), &parsed)) << names.back();
    EXPECT_EQ(parsed, value) << names.back();
  }
  EXPECT_EQ(names, expected_names);
  Enum parsed = values.front();
  EXPECT_FALSE(from_name("no such name", &parsed));
  EXPECT_EQ(parsed, values.front());
}

TEST(EnumNames, RigPresetsAndSceneTypes) {
  ExpectNamesRoundTrip(
      AllRigPresets(), &RigPresetName, &RigPresetFromName,
      {"ring5", "fisheye_helmet5", "car_surround4", "stereo_pair"});
  ExpectNamesRoundTrip(AllSceneTypes(), &SceneTypeName, &SceneTypeFromName,
                       {"room", "courtyard", "street"});
}

}  // namespace enum_names_test
}  // namespace rig_calibrator

// The extended colmap's help: COLMAP's text kept line by line, rig_calibrator
// inserted in the sorted command list, the paragraph after the list.
#include "colmap_ext/commands/colmap_help.h"

#include <gtest/gtest.h>

#include <string>

namespace rig_calibrator {
namespace colmap_help_test {

const char kParagraph[] =
    "Added by rig_calibrator (multi-camera rig calibration; the commands "
    "above\n"
    "are COLMAP 3.8's own):\n"
    "  colmap rig_calibrator help\n"
    "  colmap rig_calibrator --database_path DATABASE --image_path IMAGES \\\n"
    "      --input_path MODEL --output_path OUTPUT\n"
    "\n";

const char kHeader[] =
    "COLMAP 3.8 -- Structure-from-Motion and Multi-View Stereo\n"
    "\n"
    "Usage:\n"
    "  colmap [command] [options]\n"
    "\n"
    "Example usage:\n"
    "  colmap help [ -h, --help ]\n"
    "  ...\n"
    "\n"
    "Available commands:\n"
    "  help\n";

TEST(ExtendColmapHelp, InsertsTheCommandInOrderAndTheParagraphAfterTheList) {
  const std::string colmap_help = std::string(kHeader) +
                                  "  mapper\n"
                                  "  rig_bundle_adjuster\n"
                                  "  sequential_matcher\n"
                                  "\n";
  EXPECT_EQ(ExtendColmapHelp(colmap_help), std::string(kHeader) +
                                               "  mapper\n"
                                               "  rig_bundle_adjuster\n"
                                               "  rig_calibrator\n"
                                               "  sequential_matcher\n"
                                               "\n" +
                                               kParagraph);
}

TEST(ExtendColmapHelp, LastInTheListWhenItSortsLast) {
  const std::string colmap_help = std::string(kHeader) + "  mapper\n\n";
  EXPECT_EQ(
      ExtendColmapHelp(colmap_help),
      std::string(kHeader) + "  mapper\n  rig_calibrator\n\n" + kParagraph);
}

TEST(ExtendColmapHelp, HelpStaysFirst) {
  const std::string colmap_help = std::string(kHeader) + "  vocab_tree\n\n";
  EXPECT_EQ(
      ExtendColmapHelp(colmap_help),
      std::string(kHeader) + "  rig_calibrator\n  vocab_tree\n\n" + kParagraph);
}

TEST(ExtendColmapHelp, TextWithoutTheListGetsBothAtTheEnd) {
  EXPECT_EQ(ExtendColmapHelp("colmap\n"),
            std::string("colmap\n  rig_calibrator\n\n") + kParagraph);
}

}  // namespace colmap_help_test
}  // namespace rig_calibrator

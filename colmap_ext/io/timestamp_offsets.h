// Constant timestamp offsets between cameras, from the numeric image names
// alone, so that unsynchronized cameras (or cameras whose clocks differ)
// still group into framesets (rig_layout.h).
//
// Camera c's names are t_c = t_ref + o_c + jitter for the images taken with
// the reference camera's image t_ref. For every image of c the difference to
// the nearest reference name in the same folder is d = t_c - t_ref(nearest);
// for |o_c| below half the frame period the nearest is the partner, so the
// differences of paired images cluster at o_c, those of images whose partner
// is missing fall a frame period away. The offset is the window
// [o - tolerance, o + tolerance] holding the most differences (a sweep over
// the sorted differences: each difference starts a window of width
// 2 tolerance), then o_c = the median of the differences in it. Each counted
// difference is one pairing within the tolerance after removing o_c (two
// images of c within 2 tolerance of one reference image would both count,
// which the grouping's frame periods above the tolerance exclude).
//
// Today's grouping is kept exactly when the offsets are about 0: o_c = 0
// unless the best window pairs more images than the window around 0 does and
// at least kMinTimestampPairs of them.
#pragma once

#include <vector>

namespace rig_calibrator {

inline constexpr int kMinTimestampPairs = 3;

struct TimedName {
  int camera = -1;
  int folder = 0;  // names in different folders never pair
  long double time = 0;
};

// Per camera o_c (names' units; 0 for the reference camera and for cameras
// with no pairing evidence). `tolerance` > 0.
std::vector<long double> EstimateTimestampOffsets(
    const std::vector<TimedName>& names, int num_cameras, int reference_camera,
    long double tolerance);

}  // namespace rig_calibrator

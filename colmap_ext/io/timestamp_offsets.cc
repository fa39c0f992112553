#include "colmap_ext/io/timestamp_offsets.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace rig_calibrator {
namespace {

// The differences t_c - t_ref(nearest) of camera c's names (see the header).
std::vector<long double> NearestDifferences(
    const std::vector<TimedName>& names, const int camera,
    const std::map<int, std::vector<long double>>& reference_times) {
  std::vector<long double> differences;
  for (const TimedName& name : names) {
    if (name.camera != camera) continue;
    const auto folder = reference_times.find(name.folder);
    if (folder == reference_times.end()) continue;
    const std::vector<long double>& times = folder->second;
    const auto next = std::lower_bound(times.begin(), times.end(), name.time);
    long double best = INFINITY;
    if (next != times.end()) best = name.time - *next;
    if (next != times.begin() &&
        std::abs(name.time - *(next - 1)) < std::abs(best)) {
      best = name.time - *(next - 1);
    }
    differences.push_back(best);
  }
  std::sort(differences.begin(), differences.end());
  return differences;
}

// o_c from the sorted differences (see the header).
long double OffsetOfDifferences(const std::vector<long double>& differences,
                                const long double tolerance) {
  const auto count_in = [&](long double low, long double high) {
    return std::upper_bound(differences.begin(), differences.end(), high) -
           std::lower_bound(differences.begin(), differences.end(), low);
  };
  const long double width = 2 * tolerance;
  std::ptrdiff_t best_count = 0;
  long double best_low = 0;
  for (size_t i = 0; i < differences.size(); ++i) {
    const std::ptrdiff_t count =
        count_in(differences[i], differences[i] + width);
    // Among windows with equal counts the one nearest 0.
    if (count > best_count ||
        (count == best_count &&
         std::abs(differences[i] + tolerance) < std::abs(best_low + tolerance))) {
      best_count = count;
      best_low = differences[i];
    }
  }
  if (best_count < kMinTimestampPairs ||
      best_count <= count_in(-tolerance, tolerance)) {
    return 0;
  }
  const auto first =
      std::lower_bound(differences.begin(), differences.end(), best_low);
  return *(first + (best_count - 1) / 2) / 2 + *(first + best_count / 2) / 2;
}

}  // namespace

std::vector<long double> EstimateTimestampOffsets(
    const std::vector<TimedName>& names, const int num_cameras,
    const int reference_camera, const long double tolerance) {
  std::vector<long double> offsets(num_cameras, 0);
  std::map<int, std::vector<long double>> reference_times;
  for (const TimedName& name : names) {
    if (name.camera == reference_camera) {
      reference_times[name.folder].push_back(name.time);
    }
  }
  for (auto& [folder, times] : reference_times) {
    std::sort(times.begin(), times.end());
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (c == reference_camera) continue;
    offsets[c] = OffsetOfDifferences(
        NearestDifferences(names, c, reference_times), tolerance);
  }
  return offsets;
}

}  // namespace rig_calibrator

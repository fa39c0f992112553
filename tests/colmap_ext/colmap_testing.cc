#include "tests/colmap_ext/colmap_testing.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>

namespace rig_calibrator {
namespace testing {

int RunCommand(int (*command)(int, char**),
               std::vector<std::string> arguments) {
  arguments.insert(arguments.begin(), "rig_calibrator");
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  return command(static_cast<int>(argv.size()), argv.data());
}

void ExecuteSql(const std::string& path, const std::string& sql) {
  sqlite3* database = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &database), SQLITE_OK);
  char* message = nullptr;
  EXPECT_EQ(sqlite3_exec(database, sql.c_str(), nullptr, nullptr, &message),
            SQLITE_OK)
      << (message != nullptr ? message : "");
  sqlite3_free(message);
  sqlite3_close(database);
}

Eigen::VectorXf SiftLikeDescriptors::RandomBase() {
  Eigen::VectorXf base(128);
  for (int j = 0; j < 128; ++j) {
    base(j) = coin_(random_) ? std::abs(normal_(random_)) : 0.0f;
  }
  return base * (512.0f / std::max(base.norm(), 1e-6f));
}

colmap::FeatureDescriptor SiftLikeDescriptors::Observe(
    const Eigen::VectorXf& base, const double noise) {
  Eigen::VectorXf noisy = base;
  for (int j = 0; j < 128; ++j) {
    noisy(j) =
        std::max(0.0f, noisy(j) + static_cast<float>(noise * normal_(random_)));
  }
  return Quantize(noisy);
}

colmap::FeatureDescriptor SiftLikeDescriptors::Quantize(
    const Eigen::VectorXf& vector) {
  const Eigen::VectorXf scaled =
      vector * (512.0f / std::max(vector.norm(), 1e-6f));
  colmap::FeatureDescriptor descriptor(1, 128);
  for (int j = 0; j < 128; ++j) {
    descriptor(j) =
        static_cast<uint8_t>(std::min(255.0f, std::round(scaled(j))));
  }
  return descriptor;
}

}  // namespace testing
}  // namespace rig_calibrator

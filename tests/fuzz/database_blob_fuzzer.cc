// Fuzz target of the database reader on fuzzed rows of a valid database
// (WriteTemplateDatabase): the blob readers trust nothing of a row. Input:
// byte 0 chooses the table (keypoints, descriptors, two_view_geometries or
// the camera parameters), byte 1 the image (1-3) or pair; then int64 rows
// and cols (for cameras: the model id and width), then the blob.
#include <sqlite3.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "tests/fuzz/database_reads.h"
#include "tests/fuzz/fuzz_files.h"
#include "tests/fuzz/fuzz_templates.h"

namespace {

constexpr const char* kUpdates[] = {
    "UPDATE keypoints SET rows = ?1, cols = ?2, data = ?3 WHERE image_id = ?4;",
    "UPDATE descriptors SET rows = ?1, cols = ?2, data = ?3 WHERE image_id = "
    "?4;",
    "UPDATE two_view_geometries SET rows = ?1, cols = ?2, data = ?3 WHERE "
    "pair_id = 2147483647 * min(1, ?4) + max(1, ?4);",
    "UPDATE cameras SET model = ?1, width = ?2, params = ?3 WHERE camera_id = "
    "?4;"};

void Execute(sqlite3* database, const uint8_t* data, size_t size) {
  const int table = data[0] % 4;
  const int id = 1 + data[1] % 3;
  int64_t rows = 0;
  int64_t cols = 0;
  std::memcpy(&rows, data + 2, sizeof(rows));
  std::memcpy(&cols, data + 10, sizeof(cols));
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(database, kUpdates[table], -1, &statement, nullptr) !=
      SQLITE_OK) {
    std::abort();
  }
  sqlite3_bind_int64(statement, 1, rows);
  sqlite3_bind_int64(statement, 2, cols);
  sqlite3_bind_blob(statement, 3, data + 18, static_cast<int>(size - 18),
                    SQLITE_TRANSIENT);
  sqlite3_bind_int64(statement, 4, id);
  if (sqlite3_step(statement) != SQLITE_DONE) std::abort();
  sqlite3_finalize(statement);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  if (size < 18) return 0;
  const std::string folder = fuzz::ScratchFolder();
  static const bool written = [&folder] {
    fuzz::WriteTemplateDatabase(folder + "/valid.db");
    return true;
  }();
  (void)written;
  const std::string path = folder + "/database.db";
  fuzz::CopyFile(folder + "/valid.db", path);
  sqlite3* database = nullptr;
  if (sqlite3_open(path.c_str(), &database) != SQLITE_OK) std::abort();
  Execute(database, data, size);
  sqlite3_close(database);
  fuzz::ReadWholeDatabase(path);
  return 0;
}

// Fuzz target of the database reader on a fuzzed SQLite file: Open (schema
// checks, image list) and, when it opens, every read of every image and pair.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "tests/fuzz/database_reads.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  const std::string path = fuzz::WriteScratchFile("database.db", data, size);
  fuzz::ReadWholeDatabase(path);
  return 0;
}

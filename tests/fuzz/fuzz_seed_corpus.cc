// Writes the seed corpus of the fuzz targets (tests/fuzz/corpus/<target>/,
// committed) from the valid inputs of fuzz_templates.h, written by the
// project's own writers and COLMAP's:
//   fuzz_seed_corpus tests/fuzz/corpus
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/rig_config_io.h"
#include "tests/fuzz/fuzz_files.h"
#include "tests/fuzz/fuzz_templates.h"
#include "tests/fuzz/pipeline_case.h"

namespace {

namespace fs = std::filesystem;
using namespace rig_calibrator;

std::string Bytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << file.rdbuf();
  return bytes.str();
}

void Put(const fs::path& corpus, const std::string& target,
         const std::string& name, const std::string& bytes) {
  fs::create_directories(corpus / target);
  std::ofstream(corpus / target / name, std::ios::binary) << bytes;
}

// A seed of a target whose first byte chooses the file: the byte, the file.
std::string Selected(int selector, const std::string& path) {
  return std::string(1, static_cast<char>(selector)) + Bytes(path);
}

int Fail(const std::string& error) {
  std::cerr << "fuzz_seed_corpus: " << error << "\n";
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return Fail("usage: fuzz_seed_corpus CORPUS_FOLDER");
  const fs::path corpus(argv[1]);
  const std::string scratch = fuzz::ScratchFolder();
  std::string error;

  const std::string correspondences = scratch + "/correspondences.txt";
  if (!WriteCorrespondenceFile(correspondences, fuzz::TemplateCorrespondences(),
                               &error)) {
    return Fail(error);
  }
  Put(corpus, "correspondence", "valid.txt", Bytes(correspondences));

  const RigDescription rig = fuzz::TemplateRig();
  const std::string rig_config = scratch + "/rig_config.json";
  if (!WriteRigConfigJson(rig_config, rig, &error)) return Fail(error);
  Put(corpus, "rig_config", "valid.json", Bytes(rig_config));
  const std::string camchain = scratch + "/camchain.yaml";
  if (!WriteCamchainYaml(camchain, rig, nullptr, &error)) return Fail(error);
  Put(corpus, "camchain", "valid.yaml", Bytes(camchain));

  // Option bytes 0 (identical keys) and 1 (1 ns tolerance), see
  // rig_layout_fuzzer.cc.
  Put(corpus, "rig_layout", "keys",
      std::string(1, '\0') +
          "cam0/0001.png\ncam1/0001.png\ncam0/0002.png\ncam1/0002.png");
  Put(corpus, "rig_layout", "timestamps",
      std::string(1, '\1') +
          "cam0/1403715273262142976.png\ncam1/1403715273262142977.png\n"
          "cam0/1403715273312143104.png\ncam1/1403715273312143104.png");

  const colmap::Reconstruction model = fuzz::TemplateModel();
  const std::string model_folder = scratch + "/model";
  fs::create_directories(model_folder);
  model.WriteBinary(model_folder);
  model.WriteText(model_folder);
  const char* model_files[] = {"cameras.bin", "images.bin", "points3D.bin",
                               "cameras.txt", "images.txt", "points3D.txt"};
  for (int i = 0; i < 6; ++i) {
    Put(corpus, "model", model_files[i],
        Selected(i, model_folder + "/" + model_files[i]));
  }

  const char* rigs_frames_files[] = {"rigs.bin", "frames.bin", "rigs.txt",
                                     "frames.txt"};
  for (bool binary : {true, false}) {
    if (!WriteRigsAndFrames(model_folder, fuzz::TemplateRigsAndFrames(), binary,
                            &error)) {
      return Fail(error);
    }
  }
  for (int i = 0; i < 4; ++i) {
    Put(corpus, "rigs_frames", rigs_frames_files[i],
        Selected(i, model_folder + "/" + rigs_frames_files[i]));
  }

  const std::string database = scratch + "/database.db";
  fuzz::WriteTemplateDatabase(database);
  Put(corpus, "database_file", "valid.db", Bytes(database));

  // The template's own rows (database_blob_fuzzer.cc's layout): 3 keypoints
  // of 4 floats, 3 descriptors of 128 bytes, 2 matches, SIMPLE_RADIAL's 4
  // parameters.
  const auto blob_seed = [](int table, int64_t rows, int64_t cols,
                            size_t num_bytes) {
    std::string seed(18 + num_bytes, '\0');
    seed[0] = static_cast<char>(table);
    std::memcpy(&seed[2], &rows, sizeof(rows));
    std::memcpy(&seed[10], &cols, sizeof(cols));
    for (size_t i = 0; i < num_bytes; ++i) {
      seed[18 + i] = static_cast<char>(i % 3 == 0 ? 0x3f : i);
    }
    return seed;
  };
  Put(corpus, "database_blob", "keypoints", blob_seed(0, 3, 4, 3 * 4 * 4));
  Put(corpus, "database_blob", "descriptors", blob_seed(1, 3, 128, 3 * 128));
  Put(corpus, "database_blob", "matches", blob_seed(2, 2, 2, 2 * 2 * 4));
  Put(corpus, "database_blob", "camera", blob_seed(3, 2, 64, 4 * 8));
  // The whole-pipeline case's files (pipeline_fuzzer.cc's selector, then
  // the file).
  const std::string pipeline = scratch + "/pipeline";
  fuzz::WritePipelineCase(pipeline);
  const std::vector<std::string>& pipeline_files = fuzz::PipelineCaseFiles();
  for (size_t i = 0; i < pipeline_files.size(); ++i) {
    std::string name = pipeline_files[i];
    std::replace(name.begin(), name.end(), '/', '_');
    Put(corpus, "pipeline", name,
        Selected(static_cast<int>(i), pipeline + "/" + pipeline_files[i]));
  }
  std::cout << "fuzz_seed_corpus: wrote the seeds into " << corpus << "\n";
  return 0;
}

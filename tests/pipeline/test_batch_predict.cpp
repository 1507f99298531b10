// SPDX-License-Identifier: Apache-2.0
// A batch's file names (pipeline/batch_predict.hpp): what `predict SEQ... -o FOLDER` and
// inertialnet.batch call each sequence's rates file, and the batches they refuse.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "inertialnet/pipeline/batch_predict.hpp"
#include "inertialnet/runtime/error.hpp"
#include "inertialnet/runtime/version.hpp"

using namespace inertialnet;
namespace fs = std::filesystem;

TEST(BatchPredict, NamesASequenceByItsFolderOrFileStem) {
  const fs::path root = fs::temp_directory_path() / "inertialnet_test_batch_names";
  fs::remove_all(root);
  fs::create_directories(root / "MH_01_easy" / "mav0");
  EXPECT_EQ(batch_rates_name(root / "MH_01_easy"), "MH_01_easy.csv");
  EXPECT_EQ(batch_rates_name((root / "MH_01_easy").string() + "/"), "MH_01_easy.csv");  // a glob's "data/*/"
  EXPECT_EQ(batch_rates_name(root / "MH_01_easy" / "mav0"), "MH_01_easy.csv");           // the folder above mav0
  EXPECT_EQ(batch_rates_name(root / "run1.bag"), "run1.csv");                              // a file: its stem
  EXPECT_EQ(batch_rates_name("clip.tar.mp4"), "clip.tar.csv");
  fs::remove_all(root);
}

TEST(BatchPredict, RefusesTwoSequencesOfOneNameAndLiveSources) {
  try {
    batch_rates_paths({"a/seq", "b/seq"}, "out");
    FAIL() << "two sequences named seq were accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("would both write out/seq.csv"), std::string::npos) << e.what();
  }
  EXPECT_THROW(batch_rates_paths({"/dev/video0"}, "out"), Error);
  const auto paths = batch_rates_paths({"a/s1", "b/s2"}, "out");
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_EQ(paths[1], fs::path("out") / "s2.csv");
}

// A batch's sequences in order (named first, then the manifest's with their lines), and the
// refusal of a missing one before any is computed, a listed one as manifest:line.
TEST(BatchPredict, SequencesWithTheirManifestLinesAndTheMissingOneNamed) {
  const fs::path root = fs::temp_directory_path() / "inertialnet_test_batch_sequences";
  fs::remove_all(root);
  fs::create_directories(root / "here");
  fs::create_directories(root / "there");
  {
    std::ofstream manifest(root / "list.txt");
    manifest << "# sequences\nhere\n\nthere\ngone\n";
  }
  const auto entries = batch_sequences({root / "there"}, root / "list.txt");
  ASSERT_EQ(entries.size(), 4u);
  EXPECT_EQ(entries[0].sequence, root / "there");
  EXPECT_EQ(entries[0].line, 0u);
  EXPECT_EQ(entries[1].sequence, root / "here");
  EXPECT_EQ(entries[1].line, 2u);
  EXPECT_EQ(entries[2].line, 4u);
  EXPECT_EQ(entries[3].line, 5u);
  EXPECT_NO_THROW(require_batch_sequences_exist({entries.begin(), entries.begin() + 3}, "list.txt"));
  try {
    require_batch_sequences_exist(entries, "--manifest list.txt");
    FAIL() << "a missing listed sequence was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("--manifest list.txt:5: it lists the sequence " + (root / "gone").string() +
                                         ", which does not exist; nothing was computed."),
              std::string::npos)
        << e.what();
  }
  try {
    require_batch_sequences_exist(batch_sequences({root / "missing"}, ""), "");
    FAIL() << "a missing named sequence was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the sequence " + (root / "missing").string() + " does not exist"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(root);
}

// The provenance records the flow a weight-free run resolves to (default_flow), not the empty
// setting: a rates file written when "" meant DIS must not count as current once "" means LK.
TEST(BatchPredict, ProvenanceNamesTheWeightFreeFlowPredictRuns) {
  const fs::path root = fs::temp_directory_path() / "inertialnet_test_batch_provenance";
  fs::remove_all(root);
  fs::create_directories(root / "seq" / "mav0");
  const auto flow_of = [](const Provenance& provenance) {
    for (const auto& entry : provenance) {
      if (entry.first == "flow") return entry.second;
    }
    return std::string("(absent)");
  };
  PredictSettings settings;
  settings.sequence = root / "seq";
  EXPECT_EQ(flow_of(prediction_provenance(settings, 0)), "lk");
  settings.readout_time_s = 0.03;  // the row-linear model: DIS
  EXPECT_EQ(flow_of(prediction_provenance(settings, 0)), "dis");
  settings.flow = "lk";  // given: as it is
  EXPECT_EQ(flow_of(prediction_provenance(settings, 0)), "lk");
  // LK's settings too (issue 24: a file from LK before its smoothing is not current); none for DIS.
  const auto lk_of = [](const Provenance& provenance) {
    for (const auto& entry : provenance) {
      if (entry.first == "lk_flow") return entry.second;
    }
    return std::string("(absent)");
  };
  EXPECT_NE(lk_of(prediction_provenance(settings, 0)).find("smoothing 1 px at 752 columns"), std::string::npos)
      << lk_of(prediction_provenance(settings, 0));
  settings.flow = "dis";
  EXPECT_EQ(lk_of(prediction_provenance(settings, 0)), "(absent)");
  fs::remove_all(root);
}

// The version (0.1.0) does not change with behaviour; the provenance also names the build by its
// sources' SHA-256 (cmake/SourceIdentity.cmake), so a file another build wrote is computed again
// (tests/cli/batch.cmake checks the recomputation, tests/source_identity.cmake the identity).
TEST(BatchPredict, ProvenanceNamesTheBuildBySourceIdentity) {
  const std::string identity = build_versions().source;
  ASSERT_EQ(identity.size(), 64u) << identity;
  EXPECT_EQ(identity.find_first_not_of("0123456789abcdef"), std::string::npos) << identity;
  EXPECT_NE(identity, std::string(64, '0'));
  const fs::path root = fs::temp_directory_path() / "inertialnet_test_batch_identity";
  fs::remove_all(root);
  fs::create_directories(root / "seq" / "mav0");
  PredictSettings settings;
  settings.sequence = root / "seq";
  std::string recorded = "(absent)";
  for (const auto& [key, value] : prediction_provenance(settings, 0)) {
    if (key == "source") recorded = value;
  }
  EXPECT_EQ(recorded, "sha256 " + identity);
  fs::remove_all(root);
}

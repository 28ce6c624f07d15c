// The option table (train_options.h): one row per TrainConfig field drives the JSON form, the
// range checks and the `sadsplat train` flags.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <set>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/train_options.h"

namespace sadsplat {
namespace gaussians {
namespace {

TEST(TrainOptions, KeysAndFlagsAreUniqueAndTheJsonHasExactlyTheTablesKeys) {
  std::set<std::string> keys, flags;
  for (const TrainOption& o : trainOptions()) {
    EXPECT_TRUE(keys.insert(o.key).second) << o.key;
    if (o.flag != nullptr) {
      EXPECT_TRUE(flags.insert(o.flag).second) << o.flag;
    }
    EXPECT_GT(std::string(o.help).size(), 5u) << o.key;
  }
  const nlohmann::json j = nlohmann::json::parse(TrainConfig{}.toJson());
  EXPECT_EQ(j.size(), keys.size());
  for (const auto& [key, value] : j.items()) EXPECT_EQ(keys.count(key), 1u) << key;
}

// Every option survives the JSON round trip with a value other than its default.
TEST(TrainOptions, EveryOptionRoundTripsThroughJson) {
  TrainConfig changed;
  for (const TrainOption& o : trainOptions()) {
    const std::string text = optionText(o, changed);
    std::string other;
    if (text == "true" || text == "false") {
      other = text == "true" ? "false" : "true";
    } else if (!optionChoices(o).empty()) {
      other = optionChoices(o).back();
    } else if (text.front() == '[') {
      continue;  // the background colour: checked below
    } else {
      other = std::to_string(std::stod(text) + 1);
      if (std::stod(other) > o.max) other = std::to_string(o.max);
      if (o.key == std::string("seed") || text.find('.') == std::string::npos) {
        other = std::to_string(static_cast<long long>(std::stod(other)));
      }
    }
    setOptionFromText(o, other, changed, "test");
  }
  changed.background = {0.25f, 0.5f, 1.0f};
  const TrainConfig back = TrainConfig::fromJson(changed.toJson(), "test");
  EXPECT_EQ(back.toJson(), changed.toJson());
  EXPECT_NE(back.toJson(), TrainConfig{}.toJson());
  EXPECT_EQ(back.background[1], 0.5f);
}

TEST(TrainOptions, CheckNamesTheFirstOptionOutOfRange) {
  const auto fieldOf = [](const TrainConfig& c) -> std::string {
    try {
      c.check("cfg.json");
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), "cfg.json");
      return e.field();
    }
    return "";
  };
  EXPECT_EQ(fieldOf(TrainConfig{}), "");
  TrainConfig c;
  c.iterations = 0;
  EXPECT_EQ(fieldOf(c), "iterations");
  c = TrainConfig{};
  c.recovery_prune = 1.0;
  EXPECT_EQ(fieldOf(c), "recovery_prune");
  c = TrainConfig{};
  c.recovery_iterations = c.iterations;  // in the table's range, not below iterations
  EXPECT_EQ(fieldOf(c), "recovery_iterations");
  c = TrainConfig{};
  c.feature_dim = 33;
  EXPECT_EQ(fieldOf(c), "feature_dim");
}

// docs/GUIDE.md's table of training options names every key of the table (and no other).
TEST(TrainOptions, TheGuideListsEveryKey) {
  std::ifstream in(std::string(SADSPLAT_TEST_DATA_DIR) + "/../docs/GUIDE.md");
  ASSERT_TRUE(in) << "docs/GUIDE.md";
  std::set<std::string> listed;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `", 0) == 0) listed.insert(line.substr(3, line.find('`', 3) - 3));
  }
  for (const TrainOption& o : trainOptions()) EXPECT_EQ(listed.count(o.key), 1u) << o.key;
}

TEST(TrainOptions, TextValuesAreTypeChecked) {
  TrainConfig c;
  const auto& options = trainOptions();
  const auto find = [&](const std::string& key) {
    for (const TrainOption& o : options) {
      if (o.key == key) return o;
    }
    ADD_FAILURE() << key;
    return options.front();
  };
  setOptionFromText(find("lambda_l0"), "0.05", c, "<command line>");
  EXPECT_EQ(c.lambda_l0, 0.05);
  setOptionFromText(find("device"), "cuda", c, "<command line>");
  EXPECT_EQ(c.device, gaussians::TrainDevice::kCuda);
  // A name outside a choice's names is an error listing them.
  try {
    setOptionFromText(find("drop"), "bogus", c, "<command line>");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("drop: expected none,semantic,structure,full, got bogus"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(c.drop, gaussians::DropMode::kNone);
  EXPECT_THROW(setOptionFromText(find("iterations"), "many", c, "<command line>"), Error);
  EXPECT_THROW(setOptionFromText(find("iterations"), "2.5", c, "<command line>"), Error);
  EXPECT_THROW(setOptionFromText(find("prune_floaters"), "7", c, "<command line>"), Error);
}

}  // namespace
}  // namespace gaussians
}  // namespace sadsplat

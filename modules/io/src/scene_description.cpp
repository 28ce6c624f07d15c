#include <nlohmann/json.hpp>

#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {
namespace {

nlohmann::json parseJsonFile(const std::string& path) {
  const std::string text = readWholeFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // parse_error, or out_of_range for 1e99999
    throw Error(path, "JSON syntax", "valid JSON", e.what());
  }
}

std::vector<std::string> stringList(const nlohmann::json& doc, const std::string& path,
                                    const char* key, bool required) {
  std::vector<std::string> out;
  if (!doc.contains(key)) {
    if (required) throw Error(path, key, "a list of image names", "missing");
    return out;
  }
  const auto& list = doc.at(key);
  if (!list.is_array()) throw Error(path, key, "a list of image names", list.type_name());
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (!list[i].is_string()) {
      throw Error(path, std::string(key) + "[" + std::to_string(i) + "]", "a string",
                  list[i].type_name());
    }
    out.push_back(list[i].get<std::string>());
  }
  return out;
}

}  // namespace

std::vector<ClassInfo> readClassesJson(const std::string& path) {
  const nlohmann::json doc = parseJsonFile(path);
  if (!doc.is_object() || !doc.contains("classes") || !doc.at("classes").is_array()) {
    throw Error(path, "classes", "an object with a \"classes\" array",
                doc.is_object() ? "no \"classes\" array" : doc.type_name());
  }
  const auto& list = doc.at("classes");
  if (list.empty() || list.size() > 255) {
    throw Error(path, "classes", "1 to 255 classes (a scene without classes has no classes.json)",
                std::to_string(list.size()));
  }
  std::vector<ClassInfo> classes;
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = "classes[" + std::to_string(i) + "]";
    const auto& item = list[i];
    if (!item.is_object()) throw Error(path, where, "an object", item.type_name());
    ClassInfo c;
    if (!item.contains("name") || !item.at("name").is_string() ||
        item.at("name").get<std::string>().empty()) {
      throw Error(path, where + ".name", "a non-empty string",
                  item.contains("name") ? item.at("name").dump().substr(0, 40) : "missing");
    }
    c.name = item.at("name").get<std::string>();
    if (!names.insert(c.name).second) {
      throw Error(path, where + ".name", "a unique class name", c.name + " (a duplicate)");
    }
    if (!item.contains("color") || !item.at("color").is_array() || item.at("color").size() != 3) {
      throw Error(path, where + ".color", "[r, g, b] with integers 0..255",
                  item.contains("color") ? item.at("color").dump().substr(0, 40) : "missing");
    }
    for (int k = 0; k < 3; ++k) {
      const auto& v = item.at("color")[k];
      if (!v.is_number_integer() || v.get<int>() < 0 || v.get<int>() > 255) {
        throw Error(path, where + ".color", "[r, g, b] with integers 0..255", v.dump());
      }
      c.color[k] = static_cast<std::uint8_t>(v.get<int>());
    }
    c.prompt = c.name;
    if (item.contains("prompt")) {
      if (!item.at("prompt").is_string()) {
        throw Error(path, where + ".prompt", "a string", item.at("prompt").type_name());
      }
      c.prompt = item.at("prompt").get<std::string>();
    }
    classes.push_back(c);
  }
  return classes;
}

SplitInfo readSplitJson(const std::string& path) {
  const nlohmann::json doc = parseJsonFile(path);
  if (!doc.is_object()) throw Error(path, "top level", "an object", doc.type_name());
  SplitInfo split;
  split.train = stringList(doc, path, "train", true);
  split.test = stringList(doc, path, "test", true);
  split.labelled = stringList(doc, path, "labelled", false);
  const std::set<std::string> train(split.train.begin(), split.train.end());
  for (const auto& name : split.labelled) {
    if (!train.count(name)) {
      throw Error(path, "labelled", "names that are also in \"train\"", name);
    }
  }
  for (const auto& name : split.test) {
    if (train.count(name)) throw Error(path, "test", "names not in \"train\"", name);
  }
  return split;
}

void writeClassesJson(const std::string& path, const std::vector<ClassInfo>& classes) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : classes) {
    list.push_back({{"name", c.name},
                    {"color", {int(c.color[0]), int(c.color[1]), int(c.color[2])}},
                    {"prompt", c.prompt}});
  }
  const std::string text = nlohmann::json{{"classes", list}}.dump(2) + "\n";
  writeTextFileAtomically(path, text);
}

void writeSplitJson(const std::string& path, const SplitInfo& split) {
  const nlohmann::json doc = {
      {"train", split.train}, {"test", split.test}, {"labelled", split.labelled}};
  const std::string text = doc.dump(2) + "\n";
  writeTextFileAtomically(path, text);
}

}  // namespace io
}  // namespace sadsplat

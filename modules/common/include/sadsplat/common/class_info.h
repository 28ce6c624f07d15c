#pragma once
/// \file class_info.h
/// \brief The semantic classes of a scene: name, display colour and text prompt.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sadsplat {

/// \brief One semantic class. Its id is its index in the scene's class list.
struct ClassInfo {
  std::string name;                     ///< unique, e.g. "building"
  std::array<std::uint8_t, 3> color{};  ///< RGB used in colour label maps and semantic clouds
  std::string prompt;                   ///< text prompt for open-vocabulary backends
};

/// \brief Id of the class called `name` in `classes`, or nothing.
std::optional<std::uint32_t> findClass(const std::vector<ClassInfo>& classes,
                                       const std::string& name);

}  // namespace sadsplat

#pragma once
// Tables of broken scenes: each row edits a valid scene, and the error it
// must be refused with holds every one of the row's message parts.

#include <catch2/catch.hpp>

#include <functional>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace outburst::testing {

// `text` with the first `from` replaced by `to` (the test fails without one).
inline std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

struct BrokenScene {
  std::string scene;
  std::vector<std::string> message_parts;
};

// `read` must refuse each row's scene with a scene::Error naming its parts.
inline void check_refused(const std::vector<BrokenScene>& rows, const std::function<void(const std::string&)>& read) {
  for (const auto& row : rows) {
    INFO(row.scene);
    try {
      read(row.scene);
      FAIL("the broken scene was accepted");
    } catch (const scene::Error& e) {
      const std::string message = e.what();
      INFO(message);
      for (const auto& part : row.message_parts) CHECK_THAT(message, Catch::Contains(part));
    }
  }
}

}  // namespace outburst::testing

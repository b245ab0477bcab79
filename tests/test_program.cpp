// The command line's last resort: exceptions that escape a run become exit
// codes with a message of ours, never a raw C++ text.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>

#include "common/program.hpp"

using namespace outburst;

TEST_CASE("a run that runs out of memory ends with exit code 1 and says so", "[program]") {
  const std::string scene = std::string(OUTBURST_SOURCE_DIR) + "/cases/drainage/drainage.toml";
  std::string program = "outburst-test", scene_arg = scene, quiet = "-q";
  char* argv[] = {program.data(), scene_arg.data(), quiet.data()};
  // The log goes to stderr: catch it in a file.
  const auto log = std::filesystem::temp_directory_path() / "outburst_test_bad_alloc.log";
  std::fflush(stderr);
  const int saved = ::dup(2);
  std::FILE* file = std::fopen(log.c_str(), "w");
  ::dup2(::fileno(file), 2);
  const int code = run_program(program, "", 3, argv, [](const RunOptions&, scene::Document&) -> int {
    throw std::bad_alloc();
  });
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  std::fclose(file);
  std::stringstream text;
  text << std::ifstream(log).rdbuf();
  INFO(text.str());
  CHECK(code == 1);
  // Before: "[error] std::bad_alloc".
  CHECK_THAT(text.str(), Catch::Contains("out of memory: the run needed more memory than was free"));
  CHECK_THAT(text.str(), !Catch::Contains("std::bad_alloc"));
}

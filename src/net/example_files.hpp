#pragma once
// The subsystem files of examples/ in the source tree, embedded in the program at build time by
// src/net/embed_examples.cmake, for GET /api/examples and Onika's Open dialog.

#include <span>
#include <string_view>

namespace chimera::net {

struct ExampleFile {
  std::string_view name;   // "fig4_pid_joint.yaml"
  std::string_view title;  // the first line of its opening comment
  std::string_view text;
};

/// Every example, by file name.
std::span<const ExampleFile> example_files();

}  // namespace chimera::net

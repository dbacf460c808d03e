#pragma once
// The subsystem files POST /api/open was sent: written to a private directory of the server, so
// that `open` loads them as any file (and module processes' workers can read them there), and the
// loader's messages then named back as the client named the file.

#include <string>
#include <string_view>

#include "chimera/core/result.hpp"

namespace chimera::net {

class OpenedFiles {
 public:
  OpenedFiles() = default;
  ~OpenedFiles();  // removes the directory and what is in it
  OpenedFiles(const OpenedFiles&) = delete;
  OpenedFiles& operator=(const OpenedFiles&) = delete;

  /// Writes `text` as `name` (a file name without a directory: letters, digits, '.', '_' and '-',
  /// not starting with '.'), into a directory of mode 0700 made at the first call below $TMPDIR
  /// (or /tmp). Returns its path. One caller at a time. Not real-time safe.
  Result<std::string> write(std::string_view name, std::string_view text);
  /// `message` with the directory taken out of every path it names: "fig4.yaml:14: ...".
  [[nodiscard]] std::string as_named(std::string_view message) const;

 private:
  std::string dir_;  // "" until the first write
};

}  // namespace chimera::net

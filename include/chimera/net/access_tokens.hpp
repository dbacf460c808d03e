#pragma once
// Who may use the network control API: bearer tokens, each with a role. An operator may do
// everything the shell does; a viewer only what changes nothing (status, stats, get, help).
//
// A token file (`--token-file FILE`, and the file a generated token is written to) holds one
// token a line, optionally after its role; '#' starts a comment:
//   operator 3b1f...e0
//   viewer   9c44...17
// A line with a token alone is an operator's.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "chimera/core/result.hpp"

namespace chimera::net {

enum class Role { kViewer, kOperator };

/// "viewer" or "operator".
std::string_view role_name(Role role);

class AccessTokens {
 public:
  /// The shortest token accepted from a file: shorter ones are guessable.
  static constexpr std::size_t kMinTokenChars = 16;

  /// A fresh operator token and a fresh viewer token, 256 random bits each (getrandom), as hex.
  /// An Errc::kSystem error if the system has no randomness to give.
  static Result<AccessTokens> generate();
  /// Reads a token file. Refuses a file that other users may read (its mode must be 0600 or
  /// stricter), a line that is not `[ROLE] TOKEN`, a token shorter than kMinTokenChars or with
  /// characters other than visible ASCII, and a file without tokens. Errors name file and line.
  static Result<AccessTokens> load(const std::string& path);
  /// The same rules on text already read; `origin` names it in messages.
  static Result<AccessTokens> parse(std::string_view text, std::string_view origin);

  /// The role of a presented token, none if it is no token of this set. The comparison takes
  /// the same time wherever the first difference is, so timing tells nothing about a token.
  [[nodiscard]] std::optional<Role> role_of(std::string_view presented) const;
  /// The first token of `role`, if any.
  [[nodiscard]] std::optional<std::string> first(Role role) const;
  /// The set in the token file format.
  [[nodiscard]] std::string file_text() const;

 private:
  struct Entry {
    Role role;
    std::string token;
  };
  std::vector<Entry> entries_;
};

/// Writes `text` to a new file at `path` readable and writable by its owner only (0600),
/// replacing an older file there. Errors (Errc::kSystem) name the path.
Result<void> write_private_file(const std::string& path, std::string_view text);

/// Where a generated token file goes when none is named: $XDG_RUNTIME_DIR/chimera/ if that is
/// set, else /tmp/chimera-UID/ (made 0700, and refused unless owned by this user and closed to
/// others), as NAME.token.
Result<std::string> default_token_path(std::string_view name);

}  // namespace chimera::net

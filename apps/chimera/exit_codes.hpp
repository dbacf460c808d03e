#pragma once
// The exit codes of the chimera command (contract section 2).

namespace chimera::cli {

inline constexpr int kExitOk = 0;
/// verify: a configuration is illegal; run: a hard task failed.
inline constexpr int kExitFailed = 1;
/// An unreadable or invalid file, an unknown name, or a bad command line.
inline constexpr int kExitInvalid = 2;

}  // namespace chimera::cli

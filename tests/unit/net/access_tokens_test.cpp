// Tokens and roles of the network API: generated, read from a file, matched.

#include "chimera/net/access_tokens.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace chimera::net {
namespace {

const std::string kLong = "0123456789abcdef";

TEST(AccessTokens, GeneratedTokensAreFreshAndOfBothRoles) {
  auto a = AccessTokens::generate();
  auto b = AccessTokens::generate();
  ASSERT_TRUE(a && b);
  const auto op = a->first(Role::kOperator);
  const auto viewer = a->first(Role::kViewer);
  ASSERT_TRUE(op && viewer);
  EXPECT_EQ(op->size(), 64U);
  EXPECT_NE(*op, *viewer);
  EXPECT_NE(*op, *b->first(Role::kOperator));
  EXPECT_EQ(a->role_of(*op), Role::kOperator);
  EXPECT_EQ(a->role_of(*viewer), Role::kViewer);
  EXPECT_EQ(a->role_of(""), std::nullopt);
  EXPECT_EQ(a->role_of(op->substr(1)), std::nullopt);
  // The file text reads back as the same set.
  auto again = AccessTokens::parse(a->file_text(), "tokens");
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(again->role_of(*op), Role::kOperator);
  EXPECT_EQ(again->role_of(*viewer), Role::kViewer);
}

TEST(AccessTokens, AFileListsRolesAndTokens) {
  auto t = AccessTokens::parse(
      "# comment\n\n" + kLong + "\nviewer  v" + kLong + "  # a comment\noperator o" + kLong + "\r\n", "f");
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_EQ(t->role_of(kLong), Role::kOperator);
  EXPECT_EQ(t->role_of("v" + kLong), Role::kViewer);
  EXPECT_EQ(t->role_of("o" + kLong), Role::kOperator);
  EXPECT_EQ(t->role_of("x" + kLong), std::nullopt);
}

TEST(AccessTokens, BadFilesNameFileAndLine) {
  struct Case {
    std::string text;
    std::string message;
  };
  for (const Case& c : {Case{"admin " + kLong + "\n", "f:1: unknown role 'admin' (operator or viewer)"},
                        Case{"\nviewer short\n", "f:2: a token is at least 16 visible ASCII characters"},
                        Case{"operator a b\n", "f:1: expected [ROLE] TOKEN (ROLE: operator or viewer)"},
                        Case{kLong + "\nviewer " + kLong + "\n", "f:2: this token is already listed"},
                        Case{"# nothing\n", "f: no token in it"}}) {
    auto t = AccessTokens::parse(c.text, "f");
    ASSERT_FALSE(t) << c.text;
    EXPECT_EQ(t.error().message, c.message);
  }
}

TEST(AccessTokens, AFileOthersMayReadIsRefused) {
  const auto dir = std::filesystem::temp_directory_path() / ("chimera_tokens_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "tokens").string();
  std::ofstream(path) << "operator " << kLong << "\n";
  ::chmod(path.c_str(), 0644);
  auto t = AccessTokens::load(path);
  ASSERT_FALSE(t);
  EXPECT_NE(t.error().message.find("other users may read it (mode 0644); chmod 600"), std::string::npos)
      << t.error().message;
  ::chmod(path.c_str(), 0600);
  EXPECT_TRUE(AccessTokens::load(path));
  EXPECT_FALSE(AccessTokens::load((dir / "nosuch").string()));
  std::filesystem::remove_all(dir);
}

TEST(AccessTokens, APrivateFileIsTheOwnersOnly) {
  const auto dir = std::filesystem::temp_directory_path() / ("chimera_private_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "t").string();
  std::ofstream(path) << "old, readable by all\n";
  ::chmod(path.c_str(), 0644);
  ASSERT_TRUE(write_private_file(path, "secret\n"));
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600U);
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "secret");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace chimera::net

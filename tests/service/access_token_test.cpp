// The access token file: created once with mode 0600, refused when others may read it, and
// compared in constant time.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "scenewatch/service/access_token.h"
#include "test_data.h"

namespace scenewatch::service {
namespace {
namespace fs = std::filesystem;

class AccessTokenTest : public ::testing::Test {
 protected:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }
  static unsigned mode_of(const fs::path& path) {
    struct stat st {};
    EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
    return st.st_mode & 07777;
  }
  fs::path tmp_ = test::make_temp_dir("token");
};

TEST_F(AccessTokenTest, CreatedOnceOwnerOnly) {
  const fs::path path = tmp_ / "new-folder" / "token";
  auto first = ensure_token_file(path);
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_EQ(first->size(), 64u);
  EXPECT_EQ(first->find_first_not_of("0123456789abcdef"), std::string::npos) << *first;
  EXPECT_EQ(mode_of(path), 0600u);
  EXPECT_EQ(mode_of(path.parent_path()), 0700u);
  // Started again, the daemon keeps its token (clients holding it go on working) ...
  auto again = ensure_token_file(path);
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(*again, *first);
  auto read = read_token_file(path);
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_EQ(*read, *first);
  // ... and another file gets another token.
  auto other = ensure_token_file(tmp_ / "other");
  ASSERT_TRUE(other.ok()) << other.error().message;
  EXPECT_NE(*other, *first);
}

TEST_F(AccessTokenTest, RefusesFilesOthersMayReadOrThatAreNotTokens) {
  const fs::path open_file = tmp_ / "open";
  std::ofstream(open_file) << "0123456789abcdef0123\n";
  fs::permissions(open_file, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                                 fs::perms::others_read);
  auto r = ensure_token_file(open_file);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kPermissionDenied);
  EXPECT_NE(r.error().message.find("0644"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find(open_file.string()), std::string::npos) << r.error().message;
  EXPECT_EQ(mode_of(open_file), 0644u) << "the daemon must not silently change a user's file";

  const fs::path short_file = tmp_ / "short";
  std::ofstream(short_file) << "abc\n";
  fs::permissions(short_file, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  r = read_token_file(short_file);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("16 to 4096 characters"), std::string::npos) << r.error().message;

  fs::create_symlink(short_file, tmp_ / "link");
  r = ensure_token_file(tmp_ / "link");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("symlink"), std::string::npos) << r.error().message;

  r = read_token_file(tmp_ / "missing");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  EXPECT_FALSE(fs::exists(tmp_ / "missing")) << "the CLI's side never creates a token";

  r = ensure_token_file(tmp_);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("not a regular file"), std::string::npos) << r.error().message;
}

// In a folder every user may write to, anyone can rename the token file away and put their own in
// its place (the daemon would then accept their token): refused, unless the folder has the sticky
// bit (as /tmp has), which lets only a file's owner rename or remove it.
TEST_F(AccessTokenTest, RefusesATokenInAFolderEveryoneMayWriteWithoutTheStickyBit) {
  const fs::path shared = tmp_ / "shared";
  fs::create_directories(shared);
  const fs::path path = shared / "token";
  auto made = ensure_token_file(path);
  ASSERT_TRUE(made.ok()) << made.error().message;
  fs::permissions(shared, fs::perms::all, fs::perm_options::replace);  // 0777
  for (auto* const reader : {&ensure_token_file, &read_token_file}) {
    auto r = reader(path);
    ASSERT_FALSE(r.ok()) << "a token anyone could have swapped in is accepted";
    EXPECT_EQ(r.error().code, ErrorCode::kPermissionDenied);
    EXPECT_NE(r.error().message.find(shared.string()), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("sticky"), std::string::npos) << r.error().message;
  }
  auto fresh = ensure_token_file(shared / "fresh");
  EXPECT_FALSE(fresh.ok()) << "nor is one created there";
  EXPECT_FALSE(fs::exists(shared / "fresh"));

  fs::permissions(shared, fs::perms::all | fs::perms::sticky_bit, fs::perm_options::replace);  // 1777, as /tmp
  auto sticky = read_token_file(path);
  ASSERT_TRUE(sticky.ok()) << sticky.error().message;
  EXPECT_EQ(*sticky, *made);
  fs::permissions(shared, fs::perms::owner_all, fs::perm_options::replace);
}

TEST_F(AccessTokenTest, TokensEqualOnlyWhenIdentical) {
  const std::string token = "0123456789abcdef0123456789abcdef";
  EXPECT_TRUE(tokens_equal(token, token));
  EXPECT_FALSE(tokens_equal("", token));
  EXPECT_FALSE(tokens_equal(token.substr(0, 31), token));
  EXPECT_FALSE(tokens_equal(token + "0", token));
  EXPECT_FALSE(tokens_equal("1" + token.substr(1), token));
  EXPECT_FALSE(tokens_equal(token.substr(0, 31) + "e", token));
  EXPECT_FALSE(tokens_equal(std::string(32, '\0'), token));
  EXPECT_FALSE(tokens_equal(token, ""));
}

}  // namespace
}  // namespace scenewatch::service

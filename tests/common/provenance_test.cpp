// Provenance (common/provenance.hpp): the FNV-1a 64 config hash against the published test
// vectors, the hash of a file equal to the hash of its bytes, and the build's version and commit.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/provenance.hpp"

TEST(Provenance, ContentHashIsFnv1a64WithItsPublishedTestVectors) {
  // FNV-1a 64 test vectors (Fowler, Noll, Vo: the offset basis for "", and "a", "foobar").
  EXPECT_EQ(abuopt::content_hash(""), "fnv1a64:cbf29ce484222325");
  EXPECT_EQ(abuopt::content_hash("a"), "fnv1a64:af63dc4c8601ec8c");
  EXPECT_EQ(abuopt::content_hash("foobar"), "fnv1a64:85944171f73967e8");
}

TEST(Provenance, ConfigHashIsTheHashOfTheFileBytesAndAMissingFileIsAConfigError) {
  const auto path = std::filesystem::temp_directory_path() / ("abuopt_provenance_" + std::to_string(::getpid()) + ".yaml");
  const std::string text = "abu:\n  friction_mu: 0.02   # comment\r\n";
  std::ofstream(path, std::ios::binary) << text;
  EXPECT_EQ(abuopt::config_hash(path.string()), abuopt::content_hash(text));
  std::filesystem::remove(path);
  EXPECT_THROW(abuopt::config_hash(path.string()), abuopt::ConfigError);
}

TEST(Provenance, VersionIsTheProjectVersionAndTheCommitIsNeverEmpty) {
  EXPECT_EQ(abuopt::abuopt_version(), "0.1.0");
  const abuopt::Provenance p{abuopt::abuopt_version(), abuopt::abuopt_git_commit(), ""};
  EXPECT_FALSE(p.git_commit.empty());  // a describe string, or "unknown" outside a git checkout
}

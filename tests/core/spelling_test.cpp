#include <sph/core/spelling.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace sph {
namespace {

TEST(Spelling, EditDistanceCountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("steps", "steps"), 0u);
  EXPECT_EQ(edit_distance("step", "steps"), 1u);                 // an insertion
  EXPECT_EQ(edit_distance("stepss", "steps"), 1u);               // a deletion
  EXPECT_EQ(edit_distance("stepz", "steps"), 1u);                // a substitution
  EXPECT_EQ(edit_distance("setps", "steps"), 1u);                // two neighbours swapped
  EXPECT_EQ(edit_distance("KernelRadius", "kernelRadius"), 0u);  // letter case ignored
  EXPECT_EQ(edit_distance("colour", "color"), 1u);
  EXPECT_EQ(edit_distance("abc", "xyz"), 3u);
  EXPECT_EQ(edit_distance("neighbours", "neighbors"), 1u);
}

TEST(Spelling, ClosestNameOnlyForAMisspellingAndNeverATie) {
  const std::vector<std::string> options{"--steps", "--threads", "--neighbors", "--set", "--strict", "-o"};
  EXPECT_EQ(closest_name("--stepz", options), "--steps");
  EXPECT_EQ(closest_name("--neighbours", options), "--neighbors");
  EXPECT_EQ(closest_name("--thread", options), "--threads");
  EXPECT_EQ(closest_name("--output", options), "");  // too far from every one
  EXPECT_EQ(closest_name("--steps", options), "");   // a name that is known is not misspelt
  // "--sett" is one edit from "--set" and two from "--steps": the closer wins.
  EXPECT_EQ(closest_name("--sett", options), "--set");
  const std::vector<std::string> tied{"abcd", "abce"};
  EXPECT_EQ(closest_name("abcf", tied), "");  // one edit from each: no guess
  // Short names allow one edit, long ones more: "rn" -> "run", but "xyz" is no command.
  const std::vector<std::string> commands{"run", "compare", "bench", "validate", "render", "view", "surface"};
  EXPECT_EQ(closest_name("rn", commands), "run");
  EXPECT_EQ(closest_name("xyz", commands), "");
  EXPECT_EQ(closest_name("valdiate", commands), "validate");
  EXPECT_EQ(did_you_mean("rn", commands), " (did you mean \"run\"?)");
  EXPECT_EQ(did_you_mean("xyz", commands), "");
}

}  // namespace
}  // namespace sph

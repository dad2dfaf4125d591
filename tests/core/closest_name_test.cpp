// SPDX-License-Identifier: Apache-2.0
#include "ao/core/closest_name.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace ao {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(edit_distance("raytrace", "raytraced"), 1u);  // an insertion
  EXPECT_EQ(edit_distance("slices", "slice"), 1u);        // a deletion
  EXPECT_EQ(edit_distance("alchemy", "alchemi"), 1u);     // a substitution
  EXPECT_EQ(edit_distance("gtoa", "gtao"), 1u);           // neighbours swapped: one edit, not two
  EXPECT_EQ(edit_distance("slcies", "slices"), 1u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);      // the textbook case: k->s, e->i, +g
  EXPECT_EQ(edit_distance("GTAO", "gtao"), 0u);           // ASCII case is ignored
}

TEST(EditDistance, IsSymmetric) {
  const std::vector<std::string> words = {"", "a", "gtao", "gtoa", "volumetric", "transfer", "slcies", "slices", "xyz"};
  for (const std::string& a : words)
    for (const std::string& b : words) EXPECT_EQ(edit_distance(a, b), edit_distance(b, a)) << a << " / " << b;
}

TEST(ClosestName, NamesATypoAndNothingFarther) {
  const std::vector<std::string> methods = {"raytraced", "volumetric", "transfer", "alchemy", "gtao", "cone", "containment"};
  EXPECT_EQ(closest_name("gtoa", methods), "gtao");
  EXPECT_EQ(closest_name("raytrace", methods), "raytraced");
  EXPECT_EQ(closest_name("volumetirc", methods), "volumetric");
  EXPECT_EQ(closest_name("Alchemy", methods), "alchemy");
  EXPECT_EQ(closest_name("sphere", methods), "");  // no method is within 2 edits
  EXPECT_EQ(closest_name("", methods), "");
  EXPECT_EQ(closest_name("gtao", {}), "");
  // A third of the typed length (at least 1) is the most edits a typo makes: "xyz" (3 letters) is
  // 1 edit from "xyw" and 2 from "xww".
  const std::vector<std::string> far = {"xww"}, near = {"xyw"};
  EXPECT_EQ(closest_name("xyz", far), "");
  EXPECT_EQ(closest_name("xyz", near), "xyw");
}

TEST(ClosestName, PrefersTheNearestThenTheFirst) {
  const std::vector<std::string> names = {"radius", "slices", "slice"};
  EXPECT_EQ(closest_name("slices", names), "slices");
  EXPECT_EQ(closest_name("slicex", names), "slices");  // 1 edit from both "slices" and "slice": the first
  EXPECT_EQ(closest_name("slicess", names), "slices");  // 1 from "slices", 2 from "slice"
}

TEST(DidYouMean, IsTheSuffixOfARefusalOrNothing) {
  const std::vector<std::string> names = {"slices", "steps", "radius"};
  EXPECT_EQ(did_you_mean("slcies", names), "; did you mean 'slices'?");
  EXPECT_EQ(did_you_mean("zzzzzz", names), "");
  EXPECT_EQ(did_you_mean("slcies", "slices, steps, radius"), "; did you mean 'slices'?");
  EXPECT_EQ(did_you_mean(".pgn", ".exr, .png, .tif"), "; did you mean '.png'?");
  EXPECT_EQ(did_you_mean("x", ""), "");
  EXPECT_EQ(did_you_mean("stesp", " slices ,steps,,radius "), "; did you mean 'steps'?");
}

}  // namespace
}  // namespace ao

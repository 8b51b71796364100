// "Did you mean": the names the server suggests for an unknown model (issue
// 21 row 16). The end-to-end frame is checked in server_test.cpp.
#include "server/model_suggestions.h"

#include <gtest/gtest.h>

namespace meshstream::server {
namespace {

using Names = std::vector<std::string>;

TEST(EditDistance, CountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(edit_distance("bunny", "bunny"), 0u);
  EXPECT_EQ(edit_distance("bunnny", "bunny"), 1u);  // insertion
  EXPECT_EQ(edit_distance("buny", "bunny"), 1u);    // deletion
  EXPECT_EQ(edit_distance("bunmy", "bunny"), 1u);   // substitution
  EXPECT_EQ(edit_distance("bnuny", "bunny"), 1u);   // neighbours swapped
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("dragon", "dragon_res2"), 5u);
}

TEST(ClosestNames, SuggestsTheNearNamesClosestFirst) {
  const Names names{"armadillo", "bunny", "bunny.stl", "dragon", "fandisk", "torus"};
  EXPECT_EQ(closest_names("bunnny", names), Names{"bunny"});
  EXPECT_EQ(closest_names("Bunny", names), Names{"bunny"});
  EXPECT_EQ(closest_names("fandsik", names), Names{"fandisk"});
  EXPECT_EQ(closest_names("armadilo", names), Names{"armadillo"});
  // The file name instead of the model name.
  EXPECT_EQ(closest_names("dragon.ply", names), Names{"dragon"});
  // Closest first (distance 1 before 2), catalog order within a distance,
  // at most `limit`.
  EXPECT_EQ(closest_names("armadilo", Names{"armodilos", "armadillo", "armadillo2"}),
            (Names{"armadillo", "armodilos", "armadillo2"}));
  EXPECT_EQ(closest_names("tor", Names{"torus", "tar", "tora", "toy"}),
            (Names{"tar", "tora", "toy"}));
  EXPECT_EQ(closest_names("tor", Names{"torus", "tar", "tora", "toy"}, 2), (Names{"tar", "tora"}));
}

TEST(ClosestNames, SuggestsNothingWhenNothingIsClose) {
  const Names names{"big", "bunny", "small"};
  EXPECT_TRUE(closest_names("nope", names).empty());
  EXPECT_TRUE(closest_names("../../etc/passwd", names).empty());
  EXPECT_TRUE(closest_names("teapot", names).empty());
  EXPECT_TRUE(closest_names("", names).empty());
  EXPECT_TRUE(closest_names(std::string(200, 'b'), names).empty());
  EXPECT_TRUE(closest_names("bunny", Names{}).empty());
  // Short names need a close match: "cow" is two edits from "cat".
  EXPECT_TRUE(closest_names("cow", Names{"cat"}).empty());
}

TEST(UnknownModelMessage, NamesTheRequestTheSuggestionsAndTheListFlag) {
  EXPECT_EQ(unknown_model_message("bunnny", {"bunny"}),
            "unknown model 'bunnny': did you mean 'bunny'? (see --list)");
  EXPECT_EQ(unknown_model_message("tor", {"tar", "toy"}),
            "unknown model 'tor': did you mean 'tar' or 'toy'? (see --list)");
  EXPECT_EQ(unknown_model_message("tor", {"tar", "toy", "tora"}),
            "unknown model 'tor': did you mean 'tar', 'toy' or 'tora'? (see --list)");
  EXPECT_EQ(unknown_model_message("nope", {}), "unknown model 'nope' (see --list)");
}

TEST(Printable, EscapesControlBytesAndCutsLongNames) {
  EXPECT_EQ(printable("a\nb\x7f"), "a\\x0ab\\x7f");
  EXPECT_EQ(printable("h\xc3\xa4schen"), "h\xc3\xa4schen");  // UTF-8 stays
  EXPECT_EQ(printable(std::string(200, 'x')), std::string(128, 'x') + "...");
}

}  // namespace
}  // namespace meshstream::server

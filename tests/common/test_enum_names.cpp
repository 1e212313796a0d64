#include "common/enum_names.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace stvl {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

enum class Fruit { kApple, kBanana, kCherry };
constexpr EnumName<Fruit> kFruitNames[] = {
    {Fruit::kApple, "apple"}, {Fruit::kBanana, "banana"}, {Fruit::kCherry, "cherry"}};

std::string error_of(const std::string& text) {
  try {
    parse_enum(text, kFruitNames, "fruit");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(EnumNames, ParsesAndNamesEveryValue) {
  for (const auto& entry : kFruitNames) {
    EXPECT_EQ(parse_enum(entry.name, kFruitNames, "fruit"), entry.value);
    EXPECT_STREQ(enum_name(entry.value, kFruitNames), entry.name);
  }
  EXPECT_EQ(enum_choices(kFruitNames), "apple|banana|cherry");
}

TEST(EnumNames, UnknownNamesListTheChoicesAndSuggestTheNearest) {
  EXPECT_THAT(error_of("banan"), HasSubstr("unknown fruit 'banan'"));
  EXPECT_THAT(error_of("banan"), HasSubstr("expected apple|banana|cherry; did you mean 'banana'?"));
  EXPECT_THAT(error_of("chery"), HasSubstr("did you mean 'cherry'?"));
  EXPECT_THAT(error_of("zzzzzzzz"), Not(HasSubstr("did you mean")));
  EXPECT_THAT(error_of(""), HasSubstr("unknown fruit ''"));
}

TEST(EnumNames, EditDistanceCountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("voxel_size", "voxel_size"), 0u);
  EXPECT_EQ(edit_distance("voxel_sze", "voxel_size"), 1u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(nearest_name("voxel_sise", {"voxel_decay", "voxel_size", "decay_model"}), "voxel_size");
  EXPECT_EQ(nearest_name("q", {"voxel_size"}), "");
}

}  // namespace
}  // namespace stvl

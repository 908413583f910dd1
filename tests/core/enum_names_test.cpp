#include "core/enum_names.hpp"

#include <array>

#include <gtest/gtest.h>

namespace demo {
enum class Fruit { Apple, Pear, Plum };
constexpr std::array<rtr::EnumName<Fruit>, 3> enumNames(Fruit) {
  return {{{Fruit::Apple, "apple"}, {Fruit::Pear, "pear"}, {Fruit::Plum, "plum"}}};
}
}  // namespace demo

using demo::Fruit;

TEST(EnumNames, NamesAndValuesRoundTrip) {
  for (Fruit f : {Fruit::Apple, Fruit::Pear, Fruit::Plum}) EXPECT_EQ(rtr::enumFromName<Fruit>(rtr::enumName(f)), f);
  EXPECT_STREQ(rtr::enumName(Fruit::Pear), "pear");
  EXPECT_STREQ(rtr::enumName(Fruit(7)), "?");
  EXPECT_FALSE(rtr::enumFromName<Fruit>("Pear").has_value()) << "names are exact";
  EXPECT_FALSE(rtr::enumFromName<Fruit>("").has_value());
}

TEST(EnumNames, ChoicesListEveryNameInTableOrder) {
  EXPECT_EQ(rtr::enumChoices<Fruit>(), "apple, pear or plum");
  EXPECT_EQ(rtr::enumChoices<Fruit>("|"), "apple|pear|plum");
}

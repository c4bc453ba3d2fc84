// CSV fields as RFC 4180 has them: plain text as it is; a comma, a double quote
// or a line break puts the field in quotes, with its quotes doubled.
#include <gtest/gtest.h>

#include "core/csv.h"

namespace nadir::core {
namespace {

TEST(Csv, FieldsAreQuotedOnlyWhenTheyMustBe) {
  EXPECT_EQ(csvField("vo_feature"), "vo_feature");
  EXPECT_EQ(csvField(""), "");
  EXPECT_EQ(csvField("[0, 600]"), "\"[0, 600]\"");
  EXPECT_EQ(csvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csvField("two\nlines"), "\"two\nlines\"");
}

}  // namespace
}  // namespace nadir::core

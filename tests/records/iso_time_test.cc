// ISO 8601 timestamps as loggers print them.
#include "iso_time.h"

#include <gtest/gtest.h>

namespace mbid::records::internal {
namespace {

TEST(IsoTimeTest, ParsesTheForms) {
  Timestamp a, b, c, d;
  ASSERT_TRUE(ParseTimestamp("2026-03-01T12:00:00.125", &a));
  ASSERT_TRUE(ParseTimestamp("2026-03-01 12:00:01.250Z", &b));
  EXPECT_EQ(a.decimals, 3);  // the printed resolution is 1 ms
  EXPECT_DOUBLE_EQ(SecondsBetween(a, b), 1.125);
  // 13:00:00+01:00 is 12:00:00 UTC; "-0500" without colon also accepted.
  ASSERT_TRUE(ParseTimestamp("2026-03-01T13:00:00+01:00", &c));
  ASSERT_TRUE(ParseTimestamp("2026-03-01T07:00:00-0500", &d));
  EXPECT_DOUBLE_EQ(SecondsBetween(c, d), 0.0);
  // Across a month end in a leap year: 2028-02-29 exists, one day = 86400 s.
  Timestamp e, f;
  ASSERT_TRUE(ParseTimestamp("2028-02-28T23:59:59", &e));
  ASSERT_TRUE(ParseTimestamp("2028-02-29T23:59:59", &f));
  EXPECT_DOUBLE_EQ(SecondsBetween(e, f), 86400.0);
}

TEST(IsoTimeTest, RefusesOtherTexts) {
  Timestamp t;
  for (const char* text : {"2026-03-01", "12:00", "2026-13-01T00:00:00", "2026-03-01T12:00",
                           "2026-03-01T12:00:00.", "2026-03-01T12:00:00 junk", "0.125"}) {
    EXPECT_FALSE(ParseTimestamp(text, &t)) << text;
  }
}

}  // namespace
}  // namespace mbid::records::internal

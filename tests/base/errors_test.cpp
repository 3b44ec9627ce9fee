// InputError's message stays one readable line whatever bytes a user's file put in it: NUL as \\0,
// other control bytes and bytes that are not UTF-8 as \\xNN, UTF-8 text and line breaks as they are.
#include <gtest/gtest.h>

#include <string>

#include "base/errors.hpp"

namespace contact3d {
namespace {

TEST(InputError, QuotedBytesArePrintable) {
  const std::string quoted = std::string(
                                 "a\0b\x01"
                                 "c\x7f\xff\xc3(",
                                 9) +
                             " on Γc\n\tend";
  EXPECT_EQ(std::string(InputError(quoted).what()), "a\\0b\\x01c\\x7f\\xff\\xc3( on Γc\n\tend");
  EXPECT_EQ(std::string(InputError("plain ascii").what()), "plain ascii");
  // A UTF-8 sequence cut short at the end of the message is not UTF-8.
  EXPECT_EQ(std::string(InputError(std::string("x\xce")).what()), "x\\xce");
}

}  // namespace
}  // namespace contact3d

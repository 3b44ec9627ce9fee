// InputError's message stays one readable line whatever bytes a user's file put in it: NUL as \\0,
// other control bytes (C0, DEL, C1) and bytes that are not well-formed UTF-8 as \\xNN, UTF-8 text and
// line breaks as they are.
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
  // Not well-formed UTF-8: overlong, a surrogate, above U+10FFFF; and C1 controls (CSI), well-formed
  // but acted on by terminals.
  EXPECT_EQ(std::string(InputError(std::string("\xe0\x80\x80|\xed\xa0\x80|\xf4\x90\x80\x80|\xc2\x9b"
                                               "2J"))
                            .what()),
            "\\xe0\\x80\\x80|\\xed\\xa0\\x80|\\xf4\\x90\\x80\\x80|\\xc2\\x9b2J");
  EXPECT_EQ(std::string(InputError("µ ² — λ 😀").what()), "µ ² — λ 😀");
  // A UTF-8 sequence cut short at the end of the message is not UTF-8.
  EXPECT_EQ(std::string(InputError(std::string("x\xce")).what()), "x\\xce");
}

}  // namespace
}  // namespace contact3d

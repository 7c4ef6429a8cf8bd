// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/image.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace tofnav {
namespace {

TEST(Image, RowMajorColumnRowIndexing) {
  Image<std::uint16_t> image(4, 3);
  image(3, 1) = 7;  // column 3, row 1
  EXPECT_EQ(image.pixels()[1 * 4 + 3], 7);
  EXPECT_EQ(image.At(3, 1), 7);
  EXPECT_EQ(image.width(), 4);
  EXPECT_EQ(image.height(), 3);
}

TEST(Image, AtThrowsOutside) {
  const Image<float> image(2, 2, 1.0f);
  EXPECT_THROW(static_cast<void>(image.At(2, 0)), PreconditionError);
  EXPECT_THROW(static_cast<void>(image.At(0, -1)), PreconditionError);
  EXPECT_THROW(Image<float>(-1, 2), PreconditionError);
}

}  // namespace
}  // namespace tofnav

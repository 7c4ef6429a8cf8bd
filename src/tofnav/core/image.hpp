// SPDX-License-Identifier: BSD-3-Clause
// A dense row-major 2D image. Pixel (u, v) = (column, row), row 0 at the top.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {

template <typename T>
class Image {
 public:
  Image() = default;
  /// Zero-filled (Eigen pixel types included, whose T{} is uninitialised).
  Image(int width, int height) : Image(width, height, ZeroPixel()) {}
  Image(int width, int height, T fill)
      : width_(width), height_(height), pixels_(CheckedSize(width, height), fill) {}

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t size() const { return pixels_.size(); }
  bool empty() const { return pixels_.empty(); }
  bool Contains(int u, int v) const { return u >= 0 && v >= 0 && u < width_ && v < height_; }

  /// Unchecked access; `u` is the column, `v` the row.
  T& operator()(int u, int v) { return pixels_[Index(u, v)]; }
  const T& operator()(int u, int v) const { return pixels_[Index(u, v)]; }
  /// Bounds-checked access; throws PreconditionError outside the image.
  const T& At(int u, int v) const {
    Require(Contains(u, v), "pixel outside the image");
    return pixels_[Index(u, v)];
  }

  std::span<T> pixels() { return pixels_; }
  std::span<const T> pixels() const { return pixels_; }
  T* data() { return pixels_.data(); }
  const T* data() const { return pixels_.data(); }

  bool operator==(const Image& other) const = default;

 private:
  static T ZeroPixel() {
    if constexpr (requires { T::Zero(); }) {
      return T::Zero();
    } else {
      return T{};
    }
  }
  static std::size_t CheckedSize(int width, int height) {
    Require(width >= 0 && height >= 0, "image size must be non-negative");
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
  std::size_t Index(int u, int v) const {
    return static_cast<std::size_t>(v) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(u);
  }

  int width_ = 0;
  int height_ = 0;
  std::vector<T> pixels_;
};

}  // namespace tofnav

// SPDX-License-Identifier: BSD-3-Clause
// A small software rasteriser (orthographic, z-buffer, headlight shading) for report figures.
#include "tofnav/report/mesh_render.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kMarginFraction = 0.05;  // of the image's smaller side, around the sphere

struct Bounds {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius_mm = 0.0;
};

Bounds BoundingSphere(std::span<const MeshLayer> layers) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const MeshLayer& layer : layers) {
    for (const Eigen::Vector3d& p : layer.mesh->vertices) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  if (!(lo.array() <= hi.array()).all()) return {};
  return {.centre = 0.5 * (lo + hi), .radius_mm = 0.5 * (hi - lo).norm()};
}

Eigen::Vector3d Shade(const Eigen::Vector3d& colour, double lit, double ambient) {
  return colour * (ambient + (1.0 - ambient) * lit);
}

Eigen::Vector3d ToVector(const Rgb8& c) { return c.cast<double>(); }

struct Target {
  Image<Rgb8>& image;
  std::vector<double>& depth;
};

void DrawTriangle(const std::array<Eigen::Vector3d, 3>& s, const std::array<Eigen::Vector3d, 3>& c,
                  Target target) {
  const double area =
      (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[2].x() - s[0].x()) * (s[1].y() - s[0].y());
  if (std::abs(area) < 1e-12) return;
  const int width = target.image.width();
  const int height = target.image.height();
  const auto lo = [](double a, double b, double c2) { return std::min({a, b, c2}); };
  const auto hi = [](double a, double b, double c2) { return std::max({a, b, c2}); };
  const int u0 = std::max(0, static_cast<int>(std::floor(lo(s[0].x(), s[1].x(), s[2].x()))));
  const int v0 = std::max(0, static_cast<int>(std::floor(lo(s[0].y(), s[1].y(), s[2].y()))));
  const int u1 = std::min(width - 1, static_cast<int>(std::ceil(hi(s[0].x(), s[1].x(), s[2].x()))));
  const int v1 =
      std::min(height - 1, static_cast<int>(std::ceil(hi(s[0].y(), s[1].y(), s[2].y()))));
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const double x = u + 0.5;
      const double y = v + 0.5;
      // Barycentric weights from edge functions, positive inside for either winding.
      const double w0 = ((s[1].x() - x) * (s[2].y() - y) - (s[2].x() - x) * (s[1].y() - y)) / area;
      const double w1 = ((s[2].x() - x) * (s[0].y() - y) - (s[0].x() - x) * (s[2].y() - y)) / area;
      const double w2 = 1.0 - w0 - w1;
      if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
      const double z = w0 * s[0].z() + w1 * s[1].z() + w2 * s[2].z();
      const std::size_t at = static_cast<std::size_t>(v) * static_cast<std::size_t>(width) +
                             static_cast<std::size_t>(u);
      if (z <= target.depth[at]) continue;
      target.depth[at] = z;
      const Eigen::Vector3d rgb = (w0 * c[0] + w1 * c[1] + w2 * c[2]).cwiseMax(0.0).cwiseMin(255.0);
      target.image(u, v) = rgb.array().round().cast<std::uint8_t>().matrix();
    }
  }
}

}  // namespace

void RenderOptions::Check() const {
  Require(width_px > 0 && height_px > 0, "RenderOptions: width_px and height_px must be positive");
  Require(ambient >= 0.0 && ambient <= 1.0, "RenderOptions: ambient must be in [0, 1]");
}

OrthoCamera OrbitCamera(std::span<const MeshLayer> layers, double azimuth_rad, double elevation_rad,
                        const RenderOptions& options) {
  options.Check();
  const Bounds bounds = BoundingSphere(layers);
  // Towards the viewer: from -y (azimuth 0) turning towards +x, raised by the elevation.
  const Eigen::Vector3d back(std::cos(elevation_rad) * std::sin(azimuth_rad),
                             -std::cos(elevation_rad) * std::cos(azimuth_rad),
                             std::sin(elevation_rad));
  Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(back);
  if (right.norm() < 1e-9) right = Eigen::Vector3d::UnitX();  // looking straight down or up
  right.normalize();
  const Eigen::Vector3d up = back.cross(right);
  OrthoCamera camera;
  camera.rotation.row(0) = right.transpose();
  camera.rotation.row(1) = -up.transpose();
  camera.rotation.row(2) = back.transpose();
  camera.centre_mm = bounds.centre;
  const double half_px =
      0.5 * std::min(options.width_px, options.height_px) * (1.0 - 2.0 * kMarginFraction);
  camera.pixels_per_mm = bounds.radius_mm > 0.0 ? half_px / bounds.radius_mm : 1.0;
  return camera;
}

Image<Rgb8> RenderMeshes(std::span<const MeshLayer> layers, const OrthoCamera& camera,
                         const RenderOptions& options) {
  options.Check();
  Image<Rgb8> image(options.width_px, options.height_px, options.background);
  std::vector<double> depth(image.size(), -std::numeric_limits<double>::infinity());
  const Eigen::Vector3d image_centre(0.5 * options.width_px, 0.5 * options.height_px, 0.0);
  const Eigen::Vector3d towards_viewer = camera.rotation.row(2).transpose();
  for (const MeshLayer& layer : layers) {
    Require(layer.mesh != nullptr, "RenderMeshes: layer without a mesh");
    const TriangleMesh& mesh = *layer.mesh;
    const bool per_vertex = layer.vertex_colours.size() == mesh.vertices.size();
    for (const Eigen::Vector3i& t : mesh.triangles) {
      std::array<Eigen::Vector3d, 3> screen;
      std::array<Eigen::Vector3d, 3> colour;
      std::array<Eigen::Vector3d, 3> corner;
      for (int k = 0; k < 3; ++k) {
        const auto index = static_cast<std::size_t>(t[k]);
        Require(index < mesh.vertices.size(), "RenderMeshes: triangle index out of range");
        corner[static_cast<std::size_t>(k)] = mesh.vertices[index];
        screen[static_cast<std::size_t>(k)] =
            camera.pixels_per_mm * (camera.rotation * (mesh.vertices[index] - camera.centre_mm)) +
            image_centre;
        colour[static_cast<std::size_t>(k)] =
            ToVector(per_vertex ? layer.vertex_colours[index] : layer.colour);
      }
      const Eigen::Vector3d normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
      const double lit =
          normal.norm() > 0.0 ? std::abs(normal.normalized().dot(towards_viewer)) : 0;
      for (Eigen::Vector3d& c : colour) c = Shade(c, lit, options.ambient);
      for (Eigen::Vector3d& p : screen) p.z() += layer.depth_offset_mm * camera.pixels_per_mm;
      DrawTriangle(screen, colour, {image, depth});
    }
  }
  return image;
}

Rgb8 ErrorColour(double t) {
  // Piecewise-linear through dark blue, cyan, yellow and red: ordered in lightness for the
  // low end and clearly distinct at the high end, readable on grey shading.
  constexpr std::array<std::array<double, 3>, 4> kStops = {
      {{20, 40, 160}, {0, 200, 220}, {250, 220, 40}, {210, 30, 30}}};
  const double x = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 3.0;
  const auto i = static_cast<std::size_t>(std::min(2.0, std::floor(x)));
  const double f = x - static_cast<double>(i);
  Rgb8 out;
  for (std::size_t k = 0; k < 3; ++k) {
    out[static_cast<Eigen::Index>(k)] =
        static_cast<std::uint8_t>(std::lround((1.0 - f) * kStops[i][k] + f * kStops[i + 1][k]));
  }
  return out;
}

}  // namespace tofnav

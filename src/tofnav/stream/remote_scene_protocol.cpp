// SPDX-License-Identifier: BSD-3-Clause
// Remote Unity scene commands and the handedness conversion (docs/navigation.md, "Headset
// display").
#include "tofnav/stream/remote_scene_protocol.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"

namespace tofnav {
namespace {

constexpr double kMetresPerMm = 1e-3;

// Little-endian payload bytes (a plain append: ByteWriter's resize trips GCC 12's
// -Wstringop-overflow at -O3 when inlined many times).
class Payload {
 public:
  template <typename T>
  void Le(T value) {
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
  }
  void Text(std::string_view text) { bytes_.insert(bytes_.end(), text.begin(), text.end()); }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

void PutTransform(Payload& w, const UnityTransform& t) {
  for (int i = 0; i < 3; ++i) w.Le<float>(t.position_m[i]);
  w.Le<float>(t.rotation.x());
  w.Le<float>(t.rotation.y());
  w.Le<float>(t.rotation.z());
  w.Le<float>(t.rotation.w());
  for (int i = 0; i < 3; ++i) w.Le<float>(t.scale[i]);
}

void PutColour(Payload& w, const Rgba& c) {
  w.Le<float>(c.r);
  w.Le<float>(c.g);
  w.Le<float>(c.b);
  w.Le<float>(c.a);
}

// A rotation of the Unity frame whose columns are the images of the local axes.
Eigen::Quaternionf FromColumns(const Eigen::Vector3d& x, const Eigen::Vector3d& y,
                               const Eigen::Vector3d& z) {
  Eigen::Matrix3d m;
  m << x, y, z;
  return Eigen::Quaterniond(m).normalized().cast<float>();
}

}  // namespace

void RemoteSceneCommands::Add(RemoteSceneCommandId id, std::span<const std::uint8_t> payload) {
  Payload header;
  header.Le<std::uint32_t>(static_cast<std::uint32_t>(id));
  header.Le<std::uint32_t>(static_cast<std::uint32_t>(payload.size()));
  bytes_.insert(bytes_.end(), header.bytes().begin(), header.bytes().end());
  bytes_.insert(bytes_.end(), payload.begin(), payload.end());
  ids_.push_back(id);
}

void RemoteSceneCommands::CreatePrimitive(UnityPrimitive type) {
  Payload w;
  w.Le<std::uint32_t>(static_cast<std::uint32_t>(type));
  Add(RemoteSceneCommandId::kCreatePrimitive, w.bytes());
}

void RemoteSceneCommands::SetActive(std::uint32_t key, bool active) {
  Payload w;
  w.Le<std::uint32_t>(key);
  w.Le<std::uint32_t>(active ? 1u : 0u);
  Add(RemoteSceneCommandId::kSetActive, w.bytes());
}

void RemoteSceneCommands::SetWorldTransform(std::uint32_t key, const UnityTransform& transform) {
  Payload w;
  w.Le<std::uint32_t>(key);
  PutTransform(w, transform);
  Add(RemoteSceneCommandId::kSetWorldTransform, w.bytes());
}

void RemoteSceneCommands::SetColour(std::uint32_t key, const Rgba& colour) {
  Payload w;
  w.Le<std::uint32_t>(key);
  PutColour(w, colour);
  Add(RemoteSceneCommandId::kSetColour, w.bytes());
}

void RemoteSceneCommands::CreateText() { Add(RemoteSceneCommandId::kCreateText, {}); }

void RemoteSceneCommands::SetText(std::uint32_t key, float font_size, const Rgba& colour,
                                  std::string_view utf8) {
  Payload w;
  w.Le<std::uint32_t>(key);
  w.Le<float>(font_size);
  PutColour(w, colour);
  w.Text(utf8);
  Add(RemoteSceneCommandId::kSetText, w.bytes());
}

void RemoteSceneCommands::Say(std::string_view utf8) {
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(utf8.data()),
                                            utf8.size());
  Add(RemoteSceneCommandId::kSay, bytes);
}

void RemoteSceneCommands::Remove(std::uint32_t key) {
  Payload w;
  w.Le<std::uint32_t>(key);
  Add(RemoteSceneCommandId::kRemove, w.bytes());
}

void RemoteSceneCommands::RemoveAll() { Add(RemoteSceneCommandId::kRemoveAll, {}); }
void RemoteSceneCommands::BeginDisplayList() { Add(RemoteSceneCommandId::kBeginDisplayList, {}); }
void RemoteSceneCommands::EndDisplayList() { Add(RemoteSceneCommandId::kEndDisplayList, {}); }

void RemoteSceneCommands::SetTargetMode(std::uint32_t mode) {
  Payload w;
  w.Le<std::uint32_t>(mode);
  Add(RemoteSceneCommandId::kSetTargetMode, w.bytes());
}

std::vector<RemoteSceneCommand> TakeRemoteSceneCommands(std::vector<std::uint8_t>& stream,
                                                        const std::string& source,
                                                        std::size_t max_payload_bytes) {
  std::vector<RemoteSceneCommand> commands;
  std::size_t at = 0;
  while (stream.size() - at >= 8) {
    ByteReader header(std::span<const std::uint8_t>(stream).subspan(at, 8), source, at);
    RemoteSceneCommand command;
    command.id = header.Le<std::uint32_t>("command id");
    const std::uint32_t size = header.Le<std::uint32_t>("payload size");
    if (size > max_payload_bytes) {
      throw IoError(source, at + 4,
                    "command " + std::to_string(command.id) + " payload of " +
                        std::to_string(size) + " bytes exceeds " +
                        std::to_string(max_payload_bytes));
    }
    if (stream.size() - at - 8 < size) break;
    const auto begin = stream.begin() + static_cast<std::ptrdiff_t>(at + 8);
    command.payload.assign(begin, begin + size);
    commands.push_back(std::move(command));
    at += 8 + size;
  }
  stream.erase(stream.begin(), stream.begin() + static_cast<std::ptrdiff_t>(at));
  return commands;
}

Eigen::Vector3d UnityFromWorldPoint(const Eigen::Vector3d& point_in_world_mm) {
  return kMetresPerMm *
         Eigen::Vector3d(point_in_world_mm.x(), point_in_world_mm.y(), -point_in_world_mm.z());
}

Eigen::Vector3d WorldFromUnityPoint(const Eigen::Vector3d& point_in_unity_m) {
  return Eigen::Vector3d(point_in_unity_m.x(), point_in_unity_m.y(), -point_in_unity_m.z()) /
         kMetresPerMm;
}

Eigen::Quaterniond MirrorZ(const Eigen::Quaterniond& rotation) {
  const Eigen::Matrix3d m = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  return Eigen::Quaterniond(m * rotation.toRotationMatrix() * m).normalized();
}

UnityTransform UnitySphere(const Eigen::Vector3d& centre_in_world, double diameter_mm) {
  UnityTransform t;
  t.position_m = UnityFromWorldPoint(centre_in_world).cast<float>();
  t.scale.setConstant(static_cast<float>(diameter_mm * kMetresPerMm));
  return t;
}

UnityTransform UnityCylinder(const Eigen::Vector3d& a_in_world, const Eigen::Vector3d& b_in_world,
                             double diameter_mm) {
  const Eigen::Vector3d a = UnityFromWorldPoint(a_in_world), b = UnityFromWorldPoint(b_in_world);
  const double length_m = (b - a).norm();
  Require(length_m > 0.0, "UnityCylinder: the end points coincide");
  const Eigen::Vector3d y = (b - a) / length_m;
  const Eigen::Vector3d x = y.unitOrthogonal();
  UnityTransform t;
  t.position_m = (0.5 * (a + b)).cast<float>();
  t.rotation = FromColumns(x, y, x.cross(y));
  const auto d = static_cast<float>(diameter_mm * kMetresPerMm);
  t.scale = Eigen::Vector3f(d, static_cast<float>(0.5 * length_m), d);
  return t;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> WorldCylinderEnds(const UnityTransform& transform) {
  const Eigen::Vector3d centre = transform.position_m.cast<double>();
  const Eigen::Vector3d half = transform.rotation.cast<double>() *
                               Eigen::Vector3d(0.0, static_cast<double>(transform.scale.y()), 0.0);
  return {WorldFromUnityPoint(centre - half), WorldFromUnityPoint(centre + half)};
}

UnityTransform UnityTextPanel(const Eigen::Vector3d& position_in_world,
                              const Eigen::Vector3d& viewer_in_world,
                              const Eigen::Vector3d& up_in_world) {
  const Eigen::Vector3d p = UnityFromWorldPoint(position_in_world);
  Eigen::Vector3d z = p - UnityFromWorldPoint(viewer_in_world);  // looking at the panel
  if (z.norm() < 1e-9) z = Eigen::Vector3d::UnitZ();
  z.normalize();
  const Eigen::Vector3d up = UnityFromWorldPoint(up_in_world);
  Eigen::Vector3d y = up - up.dot(z) * z;
  if (y.norm() < 1e-9) y = z.unitOrthogonal();
  y.normalize();
  UnityTransform t;
  t.position_m = p.cast<float>();
  t.rotation = FromColumns(y.cross(z), y, z);  // a proper rotation (det +1)
  return t;
}

}  // namespace tofnav

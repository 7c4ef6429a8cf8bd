// SPDX-License-Identifier: BSD-3-Clause
// hl2ss's remote Unity scene (IPC port 3816): the command buffer and the HoloLens-world to Unity
// frame conversion (docs/navigation.md section "Headset display").
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tofnav {

/// The port of the Unity plugin's message queue on the headset.
inline constexpr int kRemoteScenePort = 3816;

enum class UnityPrimitive : std::uint32_t {
  kSphere = 0,    // 1 unit across
  kCapsule = 1,   // 2 units long along local y, 1 wide
  kCylinder = 2,  // 2 units long along local y, 1 wide
  kCube = 3,      // 1 unit across
  kPlane = 4,
  kQuad = 5,
};

/// Command ids of the remote scene (the subset tofnav sends).
enum class RemoteSceneCommandId : std::uint32_t {
  kCreatePrimitive = 0,    // u32 type; result: the new object's key (0: failed)
  kSetActive = 1,          // u32 key, u32 0/1
  kSetWorldTransform = 2,  // u32 key, f32 position xyz, rotation xyzw, scale xyz
  kSetColour = 4,          // u32 key, f32 rgba
  kCreateText = 6,         // no payload; result: key
  kSetText = 7,            // u32 key, f32 font size, f32 rgba, UTF-8 bytes
  kSay = 8,                // UTF-8 text to speech
  kRemove = 16,            // u32 key
  kRemoveAll = 17,
  kBeginDisplayList = 18,
  kEndDisplayList = 19,
  kSetTargetMode = 20,  // u32: 0 the key in each command, 1 the last created object
};

struct Rgba {
  float r = 1.0f, g = 1.0f, b = 1.0f, a = 1.0f;
  bool operator==(const Rgba&) const = default;
};

/// A Unity world transform: metres, left-handed, as the plugin's SetPositionAndRotation and
/// localScale take it.
struct UnityTransform {
  Eigen::Vector3f position_m = Eigen::Vector3f::Zero();
  Eigen::Quaternionf rotation = Eigen::Quaternionf::Identity();
  Eigen::Vector3f scale = Eigen::Vector3f::Ones();  // dimensionless factors of the primitive
};

/// A command buffer: little-endian `u32 id, u32 payload size, payload`, several per push; the
/// plugin answers one u32 per command in order.
class RemoteSceneCommands {
 public:
  void CreatePrimitive(UnityPrimitive type);
  void SetActive(std::uint32_t key, bool active);
  void SetWorldTransform(std::uint32_t key, const UnityTransform& transform);
  void SetColour(std::uint32_t key, const Rgba& colour);
  void CreateText();
  void SetText(std::uint32_t key, float font_size, const Rgba& colour, std::string_view utf8);
  void Say(std::string_view utf8);
  void Remove(std::uint32_t key);
  void RemoveAll();
  void BeginDisplayList();
  void EndDisplayList();
  void SetTargetMode(std::uint32_t mode);

  std::span<const std::uint8_t> bytes() const { return bytes_; }
  /// The id of every command, in order (the results come back in this order).
  const std::vector<RemoteSceneCommandId>& ids() const { return ids_; }
  std::size_t count() const { return ids_.size(); }
  bool empty() const { return ids_.empty(); }

 private:
  void Add(RemoteSceneCommandId id, std::span<const std::uint8_t> payload);
  std::vector<std::uint8_t> bytes_;
  std::vector<RemoteSceneCommandId> ids_;
};

/// One decoded command (the fake server of the tests).
struct RemoteSceneCommand {
  std::uint32_t id = 0;
  std::vector<std::uint8_t> payload;
};

/// Splits complete commands off the front of `stream` (bytes received so far); an incomplete
/// tail stays in it. Throws IoError naming `source` when a size exceeds `max_payload_bytes`.
std::vector<RemoteSceneCommand> TakeRemoteSceneCommands(std::vector<std::uint8_t>& stream,
                                                        const std::string& source,
                                                        std::size_t max_payload_bytes = 1 << 20);

// --- Frames: HoloLens world (right-handed, mm) -> Unity scene (left-handed, metres) ------------

/// (x, y, z) [mm] -> (x, y, -z) / 1000 [m].
Eigen::Vector3d UnityFromWorldPoint(const Eigen::Vector3d& point_in_world_mm);
/// The inverse: (x, y, z) [m] -> 1000 (x, y, -z) [mm].
Eigen::Vector3d WorldFromUnityPoint(const Eigen::Vector3d& point_in_unity_m);
/// R -> M R M with M = diag(1, 1, -1) (its own inverse, so this converts both ways).
Eigen::Quaterniond MirrorZ(const Eigen::Quaterniond& rotation);

/// A sphere of `diameter_mm` centred on `centre_in_world`.
UnityTransform UnitySphere(const Eigen::Vector3d& centre_in_world, double diameter_mm);
/// A cylinder (or capsule) of `diameter_mm` from `a_in_world` to `b_in_world` (distinct points):
/// centred between them, local y along b - a, scale (d, |b - a| / 2, d) in metres.
UnityTransform UnityCylinder(const Eigen::Vector3d& a_in_world, const Eigen::Vector3d& b_in_world,
                             double diameter_mm);
/// The end points in `world` [mm] of a cylinder placed by `transform` (bottom, top).
std::pair<Eigen::Vector3d, Eigen::Vector3d> WorldCylinderEnds(const UnityTransform& transform);
/// A text panel at `position_in_world` facing a viewer at `viewer_in_world`, upright along
/// `up_in_world` (Unity's text is read looking along its local +z).
UnityTransform UnityTextPanel(const Eigen::Vector3d& position_in_world,
                              const Eigen::Vector3d& viewer_in_world,
                              const Eigen::Vector3d& up_in_world);

}  // namespace tofnav

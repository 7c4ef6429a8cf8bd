// SPDX-License-Identifier: BSD-3-Clause
// tofnav verify's OpenIGTLink messages (docs/navigation.md section 7).
#include "tofnav/stream/verify_messages.hpp"

#include <algorithm>
#include <cstdio>

#include "tofnav/stream/igtl_codec.hpp"

namespace tofnav {

NamedMessage EncodeLandmarksGreeting(const std::vector<Landmark>& landmarks) {
  std::vector<IgtlPoint> points;
  for (const Landmark& l : landmarks) {
    points.push_back(
        {l.name, "Landmark", {255, 220, 0, 255}, RasFromImage() * l.in_image, 3.0, ""});
  }
  return {"Landmarks", EncodeIgtlMessage("POINT", "Landmarks", 0, IgtlPointContent(points))};
}

std::vector<NamedMessage> EncodeLandmarkCheck(const LandmarkCheck& check, double timestamp_s) {
  const std::uint64_t ts = IgtlTimestamp(std::max(0.0, timestamp_s));
  std::vector<NamedMessage> out;
  out.push_back({"VerifyStatus", EncodeIgtlMessage("STRING", "VerifyStatus", ts,
                                                   IgtlStringContent(check.StatusLine()))});
  std::vector<IgtlPoint> touched;
  for (const LandmarkTouch& t : check.touches()) {
    char name[96];
    std::snprintf(name, sizeof name, "%s %.2f mm",
                  check.landmarks()[static_cast<std::size_t>(t.landmark)].name.c_str(), t.error_mm);
    const std::array<std::uint8_t, 4> colour = t.pass ? std::array<std::uint8_t, 4>{0, 200, 0, 255}
                                                      : std::array<std::uint8_t, 4>{220, 0, 0, 255};
    touched.push_back({name, "Touch", colour, RasFromImage() * t.tip_in_image, 2.0, ""});
  }
  if (!touched.empty()) {
    out.push_back({"VerifyTouches",
                   EncodeIgtlMessage("POINT", "VerifyTouches", ts, IgtlPointContent(touched))});
  }
  return out;
}

}  // namespace tofnav

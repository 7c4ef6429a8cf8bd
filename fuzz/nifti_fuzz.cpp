// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: NIfTI-1 header and voxels (.nii or .nii.gz) decoded from memory.
#include <cstddef>
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/volume/nifti.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const tofnav::CtVolume volume = tofnav::DecodeNifti(std::span(data, size), "fuzz.nii");
    volume.Check();  // a decoded volume must be valid (PreconditionError would crash here)
  } catch (const tofnav::IoError&) {
    // malformed input: the expected outcome
  }
  return 0;
}

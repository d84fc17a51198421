// Reading EXRs back in tests: every channel bit for bit, as stored.
#pragma once

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <string>
#include <vector>

namespace tessera::testing {

// Every channel of an EXR (RGB and the variance layer), as floats, channel
// after channel: two images are identical when these vectors are equal.
inline std::vector<float> exr_channels(const std::string& path) {
  Imf::InputFile file(path.c_str());
  const Imath::Box2i dw = file.header().dataWindow();
  const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  std::vector<std::string> names;
  for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) names.push_back(it.name());
  std::vector<float> data(static_cast<size_t>(w) * h * names.size());
  Imf::FrameBuffer fb;
  for (size_t c = 0; c < names.size(); ++c) {
    float* base = data.data() + c * w * h - dw.min.x - dw.min.y * w;
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(base), sizeof(float), sizeof(float) * w));
  }
  file.setFrameBuffer(fb);
  file.readPixels(dw.min.y, dw.max.y);
  return data;
}

}  // namespace tessera::testing

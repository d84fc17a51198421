// A parsed scene as bytes: the master parses the scene file once and sends
// the result to every rank, so workers never read scene, mesh or texture
// files themselves.
#pragma once

#include "comm/transport.h"
#include "scene/scene_desc.h"

namespace tessera {

Bytes encode_scene(const SceneDesc& desc);
// Throws std::runtime_error for bytes that are not a scene.
SceneDesc decode_scene(const Bytes& bytes);

}  // namespace tessera

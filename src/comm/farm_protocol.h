// The messages of the render farm (rank 0 = master, others = workers).
//
//   setup     master -> all (broadcast): the parsed scene and the guide
//             cache every rank starts from, or the error that stops them.
//   Hello     worker -> master: how many threads it renders with, and its backend.
//   PassStart master -> worker: a pass begins (sample range is in the jobs),
//             with the integrator specialisation it runs (--guide auto's
//             trial renders some passes unguided).
//   Request   worker -> master: the tiles it finished (pixel accumulators
//             and counters) and a request for `capacity` more. A worker
//             keeps kRequestsInFlight requests open so it never waits idle
//             for its next tiles. `interrupted`: the worker was signalled
//             (the master stops the farm after this pass).
//   Jobs      master -> worker: tiles to render, each with its pixel
//             accumulators so far (so samples add in the same order as in
//             a local render: the image is bit-identical); empty = none
//             left in this pass.
//   Stop      master -> worker: the render is over.
//   Error     worker -> master: a worker failed (the master reports it and
//             ends the job).
// After a guided pass, every rank all-reduces the guide's accumulators
// (--guide-sync pass) and folds them: identical sums, identical fields on
// every rank. After an unguided pass, none does.
#pragma once

#include <string>
#include <vector>

#include "comm/wire.h"
#include "render/film.h"
#include "render/render_tile.h"

namespace tessera {

enum FarmTag : int32_t { kTagHello = 1, kTagPassStart, kTagRequest, kTagJobs, kTagStop, kTagError };

constexpr uint32_t kRequestsInFlight = 2;

struct FarmSetup {
  std::string error;  // non-empty: the master could not start; workers exit
  Bytes scene;        // encode_scene
  Bytes guide;        // Guide::save bytes (either kind), empty without guiding
  template <class Archive>
  void serialize(Archive& ar) {
    ar(error, scene, guide);
  }
};

struct FarmHello {
  int32_t threads = 0;
  std::string backend;  // embree, bvh, cuda
  template <class Archive>
  void serialize(Archive& ar) {
    ar(threads, backend);
  }
};

struct TileWork {
  TileJob job;
  std::vector<PixelAccum> pixels;  // row-major, (x1 - x0) * (y1 - y0)
  std::vector<Splat> splats;       // results only: the tile's light-path splats, in order
  template <class Archive>
  void serialize(Archive& ar) {
    ar(raw_value(job), raw(pixels), raw(splats));
  }
};

struct TileRequest {
  uint32_t capacity = 0;
  std::vector<TileWork> results;
  TileCounters counters;  // of the results
  bool interrupted = false;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(capacity, results, raw_value(counters), interrupted);
  }
};

struct TileJobs {
  std::vector<TileWork> jobs;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(jobs);
  }
};

struct FarmError {
  std::string message;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(message);
  }
};

struct FarmPassStart {
  uint32_t specialisation = 0;
  bool guided_roulette = false;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(specialisation, guided_roulette);
  }
};

struct FarmEmpty {
  template <class Archive>
  void serialize(Archive&) {}
};

}  // namespace tessera

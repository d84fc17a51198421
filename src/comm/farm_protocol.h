// The messages of the render farm (rank 0 = master, others = workers).
//
//   setup     master -> all (broadcast): the parsed scene and the guide
//             cache every rank starts from, or the error that stops them.
//   Hello     worker -> master: how many threads it renders with, and its backend.
//   PassStart master -> worker: pass `pass` begins (sample range is in the
//             jobs), with the integrator specialisation it runs (--guide
//             auto's trial renders some passes unguided), and the master's
//             guide for a rank that missed a fold (left out of a pass, or
//             late to join).
//   Request   worker -> master: the tiles it finished (pixel accumulators
//             and counters) and a request for `capacity` more. A worker
//             keeps kRequestsInFlight requests open so it never waits idle
//             for its next tiles. `interrupted`: the worker was signalled
//             (the master stops the farm after this pass).
//   Jobs      master -> worker: tiles to render, each with its pixel
//             accumulators so far (so samples add in the same order as in
//             a local render: the image is bit-identical); empty = none
//             left for it in this pass.
//   Round     worker -> master: after a guided pass, the rank's
//             accumulators of one round of the guide's learning; master ->
//             worker: their sum over every rank (the master's own, and its
//             stand-ins for ranks left out), which every rank folds.
//   Ping/Pong worker -> master -> worker: a worker that has waited a while
//             asks whether the master is still there.
//   Stop      master -> worker: the render is over; the worker answers Bye.
//   Error     worker -> master: a worker failed (the master reports it and
//             ends the job).
// Every message but Hello, Ping/Pong, Stop, Bye and Error names its pass: a
// rank that falls silent is left out of the pass (docs/farm.md, "A silent
// rank"), and what it says about that pass when it wakes is ignored.
//
// The schema sees plain structs only (render/tile_job.h, render/film.h'
// accumulators), never the integrator: scripts/check_layers.py holds it so.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "comm/wire.h"
#include "render/film.h"
#include "render/tile_job.h"

namespace tessera {

enum FarmTag : int32_t {
  kTagHello = 1,
  kTagPassStart,
  kTagRequest,
  kTagJobs,
  kTagStop,
  kTagError,
  kTagRound,
  kTagPing,
  kTagPong,
  kTagBye
};

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

// A batch's counters (TileCounters, render/render_tile.h) as a request
// carries them: their bytes. TileCounters holds the integrator's
// PathCounters, which the schema need not see, so the schema fixes only
// their size: a counter added there stops to_wire and from_wire compiling
// until kWords follows (the farm's messages and checkpoints change with it).
struct WireCounters {
  static constexpr size_t kWords = 20;
  uint64_t words[kWords] = {};

  template <class Counters>
  static WireCounters to_wire(const Counters& c) {
    check_layout<Counters>();
    WireCounters w;
    std::memcpy(w.words, &c, sizeof(w.words));
    return w;
  }
  template <class Counters>
  Counters from_wire() const {
    check_layout<Counters>();
    Counters c;
    std::memcpy(&c, words, sizeof(words));
    return c;
  }

 private:
  template <class Counters>
  static constexpr void check_layout() {
    static_assert(std::is_trivially_copyable_v<Counters> && sizeof(Counters) == sizeof(words),
                  "TileCounters changed: update WireCounters::kWords");
  }
};

struct TileRequest {
  uint32_t pass = 0;
  uint32_t capacity = 0;
  std::vector<TileWork> results;
  WireCounters counters;  // of the results
  bool interrupted = false;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(pass, capacity, results, raw_value(counters), interrupted);
  }
};

struct TileJobs {
  uint32_t pass = 0;
  std::vector<TileWork> jobs;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(pass, jobs);
  }
};

// One round of a guided pass's learning: a rank's accumulators, or their sum.
struct GuideRound {
  uint32_t pass = 0;
  uint32_t round = 0;
  std::vector<uint64_t> words;
  template <class Archive>
  void serialize(Archive& ar) {
    ar(pass, round, raw(words));
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
  uint32_t pass = 0;
  uint32_t specialisation = 0;
  bool guided_roulette = false;
  Bytes guide;  // Guide::save bytes for a rank whose guide missed a fold; else empty
  template <class Archive>
  void serialize(Archive& ar) {
    ar(pass, specialisation, guided_roulette, raw(guide));
  }
};

struct FarmEmpty {
  template <class Archive>
  void serialize(Archive&) {}
};

}  // namespace tessera

// For the emulator's tests: the built-in rig without friction or sensor noise, so a response is
// the linear chain's exact one and can be held against the model core's closed forms.
#pragma once

#include "rig.hpp"

namespace vibid::emu {

inline RigSpec QuietRig() {
  RigSpec r = DefaultRig();
  r.coulomb_n = {0.0, 0.0};
  for (auto& s : r.load_cells) s.noise_rms = 0.0;
  for (auto& s : r.accelerometers) s.noise_rms = 0.0;
  return r;
}

}  // namespace vibid::emu

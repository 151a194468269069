// select-scenario (wire command 0x70, emulator only): the scenario names and their parameters.
//
//   name      params[0]            params[1]            params[2]              params[3]
//   idle      -                    -                    -                      -
//   hammer    mass hit (1..n, **)  peak force N (100)   mean spacing s (*)     configuration
//   shaker    frequency Hz (16)    amplitude N (10)     hand push N (0: none)  -
//   push      amplitude N (10)     -                    -                      -
//   step      mass pulled (1..n)   pull force N (20)    hold s (1.0)           configuration
//   tone      frequency Hz (1000)  amplitude, fraction of each converter's range (0.5, <= 1)
//             a sine generator on the four converter inputs (the rig at rest): each channel
//             converts it at its own sampling instant, so their phases show the instants
//   operate   RMS force N (2)      band edge Hz (***)   mass driven (1..n, **)  hand push N (0)
//             the chain in operation: band-limited Gaussian force on the mass driven, measured
//             by load cell 1 (so the observer's residual d-hat - F can be formed), from the
//             start; a 4th-order Butterworth band, flat below the edge (BandLimitedNoise); with
//             a hand push (N > 0) as the shaker's, on the last mass, measured by load cell 2
//
// A zero parameter takes the default in brackets; (*) the hammer's spacing is left 0 here and
// set from the rig when the scenario is selected (DefaultHammerSpacingS); (**) the hammer's mass
// left 0 is the rig file's "hammer_mass", else the last mass (the step's: the last mass; the
// operate scenario's as the hammer's); (***) operate's band edge left 0 is set from the rig when
// the scenario is selected (DefaultOperateBandHz: 50 Hz, or twice the highest mode), at least
// 1 Hz when given, and lowered to 0.4 of the sample rate at the start.
// configuration: 0 the chain, k (1..n) mass k alone on spring k (the mass tests); with a mass
// alone, the mass parameter defaults to it and must not name another. n is the rig's number of
// masses (1 to 4). The shaker always drives the last mass; operate drives the chain.
#pragma once

#include "rig.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/refusal.hpp"

namespace vibid::emu {

/// @returns kOk with `out` set; kInvalidArgument for an unknown name or a parameter out of range
///          (negative, not finite, a mass or configuration the rig does not have), with `why`
///          (if given) naming which: kUnknownScenario, or kScenarioParameter and its index.
///          `hammer_mass`: the 0-based mass the hammer hits when its parameter is 0 (the rig
///          file's "hammer_mass"), or kUnmounted for the last mass.
Status ParseScenario(const wire::ScenarioRequest& request, int dofs, Scenario& out,
                     wire::Refusal* why = nullptr, int hammer_mass = kUnmounted);

}  // namespace vibid::emu

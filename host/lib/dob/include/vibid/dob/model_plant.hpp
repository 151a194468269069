// The design's view of a model file: the nominal transfer function and the M, C, K row.
#pragma once

#include "vibid/dob/design.hpp"
#include "vibid/model/model.hpp"

namespace vibid::dob {

/// Receptance from a force at input_dof to the displacement at output_dof (model core,
/// ModelTransferFunction) and row input_dof of M, C, K. DOFs 0-based; InputError when out of range.
NominalPlant PlantFromModel(const model::Model& model, int input_dof, int output_dof);

}  // namespace vibid::dob

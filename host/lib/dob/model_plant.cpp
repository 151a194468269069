#include "vibid/dob/model_plant.hpp"

#include "vibid/model/transfer_function.hpp"

namespace vibid::dob {

NominalPlant PlantFromModel(const model::Model& model, int input_dof, int output_dof) {
  const model::TransferFunction tf =
      model::ModelTransferFunction(model, input_dof, output_dof, model::FrfKind::kReceptance);
  NominalPlant plant;
  plant.receptance_num = tf.num;
  plant.receptance_den = tf.den;
  plant.m_row = model.m_kg.row(input_dof).transpose();
  plant.c_row = model.c_ns_per_m.row(input_dof).transpose();
  plant.k_row = model.k_n_per_m.row(input_dof).transpose();
  return plant;
}

}  // namespace vibid::dob

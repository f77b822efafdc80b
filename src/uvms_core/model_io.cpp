// Pinocchio's text archive, in its own translation unit: Boost.Serialization is heavy to
// compile and only runs once per model.
#include <pinocchio/serialization/model.hpp>

#include "dynamics.hpp"

namespace uvms {

Model model_from_text(const std::string& text) {
  Model model;
  try {
    model.loadFromString(text);
  } catch (const std::exception& exc) {
    throw InputError(std::string("cannot read the Pinocchio model text: ") + exc.what());
  }
  return model;
}

}  // namespace uvms

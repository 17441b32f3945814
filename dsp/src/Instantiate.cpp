// Explicit instantiations: compiles every dsp template for both sample types in one place, so
// a float-only or double-only mistake fails the library build rather than a distant user.
#include "rosin/dsp.h"

namespace rosin::dsp {
template class DelayLine<float>;
template class DelayLine<double>;
template class StringWaveguide<float>;
template class StringWaveguide<double>;
template class ConductionBank<float>;
template class ConductionBank<double>;
template class ThermalContact<float>;
template class ThermalContact<double>;
template class BowJunction<float>;
template class BowJunction<double>;
template class BowedString<float>;
template class BowedString<double>;
template class ModalBody<float>;
template class ModalBody<double>;
} // namespace rosin::dsp

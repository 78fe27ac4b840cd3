// The key of waveform iterations that the solid and the fluid section take for every model,
// declared once beside its reader (the coupler's settings, coupler/src/settings.cpp).
#include "fsi/common/waveform.hpp"

namespace fsi {

std::vector<schema::Key> window_keys() {
  using namespace schema;
  return {
      integer("substeps",
              "time steps of this solver in one coupling window time.dt (waveform iterations with subcycling: the "
              "interface data are exchanged as samples over the window and interpolated in time); 1 = one step per "
              "window, as without waveforms. More than 1 needs a solver that declares substep support")
          .def("1")
          .ge(1)
          .le(1000),
  };
}

}  // namespace fsi

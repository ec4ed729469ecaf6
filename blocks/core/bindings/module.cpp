// module.cpp: attitude_fmu._core, the C core bound into Python (nanobind): the estimator's
// pipeline and methods (pipeline.cpp), its stages (stages.cpp) and the simulation
// (systems/simulation/core/bindings/simulation.cpp).
#include <nanobind/nanobind.h>

namespace nb = nanobind;

void bind_pipeline(nb::module_ &m);
void bind_stages(nb::module_ &m);
void bind_simulation(nb::module_ &m);

NB_MODULE(_core, m)
{
    m.doc() = "The C core of attitude_fmu: every per-sample step, and loops over arrays of samples.";
    bind_pipeline(m);
    bind_stages(m);
    bind_simulation(m);
}

// pipeline.cpp: the estimator's C core bound into attitude_fmu._core: parameter validation, the
// methods' steppers, the causal pipeline (over arrays: the batch path; per sample: the online
// estimator), the offline smoother, the quaternion array helpers and the attitude error (errors.h).
// Arrays are C-contiguous float64 (inputs converted where needed; outputs written in place, never
// converted). Every refusal of the core is raised as ValueError with its message.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <vector>

extern "C" {
#include "errors.h"
#include "filters/sensor_frame.h"
#include "filters/tseng.h"
#include "methods/registry.h"
#include "methods/wiener_local.h"
#include "params.h"
#include "pipeline/causal.h"
#include "pipeline/offline.h"
#include "pipeline/online.h"
#include "quaternion.h"
#include "stages/scale_error.h"
}

#include "threads.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

constexpr size_t MESSAGE_SIZE = 2048;

template <typename T, typename Shape> using In = nb::ndarray<const T, Shape, nb::c_contig, nb::device::cpu>;
template <typename T, typename Shape> using Out = nb::ndarray<T, Shape, nb::c_contig, nb::device::cpu>;
using Rows3 = In<double, nb::shape<-1, 3>>;
using Out3 = Out<double, nb::shape<-1, 3>>;
using Out4 = Out<double, nb::shape<-1, 4>>;
using Out1 = Out<double, nb::shape<-1>>;
using Vec = std::array<double, 3>;
using Array = nb::ndarray<nb::numpy, double>;

// a refusal of the core: 0 passes, else ValueError(message)
void check(int status, const char *message)
{
    if (status != 0) throw nb::value_error(message);
}

// a new numpy array of shape holding values
Array array_of(const double *values, std::initializer_list<size_t> shape)
{
    size_t n = 1;
    for (size_t s : shape) n *= s;
    double *data = new double[n];
    if (n > 0) std::memcpy(data, values, n * sizeof(double)); // (values may be null where there are none)
    nb::capsule owner(data, [](void *p) noexcept { delete[] static_cast<double *>(p); });
    return Array(data, shape, owner);
}

// the values given for tuning parameters (a mapping name -> value, or None) as the core takes
// them: a value that is a Python int or float (not a bool) as itself, any other as NaN, shown by
// its repr
struct Given {
    std::vector<std::string> names, shown;
    std::vector<nb::object> values;
    std::vector<AfGiven> list;

    explicit Given(nb::handle params)
    {
        if (params.is_none()) return;
        nb::dict items = nb::borrow<nb::dict>(nb::handle(reinterpret_cast<PyObject *>(&PyDict_Type))(params));
        names.reserve(items.size());
        shown.reserve(items.size());
        for (auto [key, value] : items) {
            names.emplace_back(nb::str(key).c_str());
            values.push_back(nb::borrow(value));
            bool number = (PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr())) && !PyBool_Check(value.ptr());
            // shown by the core's repr where it is Python's (a float's), else by the value's own
            shown.emplace_back(PyFloat_CheckExact(value.ptr()) ? "" : nb::repr(value).c_str());
            double v = number ? PyFloat_AsDouble(value.ptr()) : NAN;
            if (number && v == -1.0 && PyErr_Occurred()) throw nb::python_error();
            list.push_back(AfGiven{nullptr, v, nullptr});
        }
        for (size_t k = 0; k < list.size(); k++) {
            list[k].name = names[k].c_str();
            list[k].shown = shown[k].empty() ? nullptr : shown[k].c_str();
        }
    }
    const AfGiven *data() const { return list.data(); }
    int size() const { return static_cast<int>(list.size()); }
    // the Python value given under name
    nb::object value(const char *name) const
    {
        for (size_t k = 0; k < names.size(); k++)
            if (names[k] == name) return values[k];
        return nb::none();
    }
};

// the stage of a name: a method's or "gyro_offset", "heading"
int stage_index(const std::string &name)
{
    for (int i = 0; i < AF_N_STAGES; i++)
        if (name == AF_STAGES[i].name) return i;
    throw nb::value_error(("no stage is called " + name).c_str());
}

const char *optional_name(const std::optional<std::string> &name)
{
    return name ? name->c_str() : nullptr;
}

int method_of(const std::optional<std::string> &name)
{
    char message[MESSAGE_SIZE];
    int index = method_index(optional_name(name), message, sizeof message);
    check(index < 0, message);
    return index;
}

// resolved values (AF_N_PARAMS) of a stage as a dict name -> float or None, in the stage's order
nb::dict resolved_dict(int stage, const double *resolved)
{
    nb::dict out;
    for (int i = 0; i < AF_STAGES[stage].n_params; i++) {
        const AfStageParam &p = AF_STAGES[stage].params[i];
        double v = resolved[p.index];
        out[p.name] = std::isnan(v) ? nb::none() : nb::cast(v);
    }
    return out;
}

// resolved values given as a dict name -> float or None (a stage's resolve_params) into AF_N_PARAMS
void resolved_values(nb::dict params, double *values)
{
    for (int i = 0; i < AF_N_PARAMS; i++) values[i] = NAN;
    for (auto [key, value] : params) {
        int index = param_index(nb::str(key).c_str());
        if (index < 0) throw nb::value_error(("no tuning parameter is called " + std::string(nb::str(key).c_str())).c_str());
        values[index] = value.is_none() ? NAN : nb::cast<double>(value);
    }
}

// a Python source of discrete filters for the core (AfZoh): callable(Ts) -> an object with Ad
// (n x n), Bd, C (n) and D, python-control's c2d of the method's design
struct PythonZoh {
    nb::handle callable;
    std::exception_ptr error;
    AfZoh zoh{hold, this};

    explicit PythonZoh(nb::handle callable) : callable(callable) {}

    static int hold(void *context, double Ts, DiscreteFilter *out, char *message, size_t size)
    {
        auto *self = static_cast<PythonZoh *>(context);
        try {
            nb::object disc = self->callable(Ts);
            auto Ad = nb::cast<In<double, nb::ndim<2>>>(disc.attr("Ad"));
            auto Bd = nb::cast<In<double, nb::ndim<1>>>(disc.attr("Bd"));
            auto C = nb::cast<In<double, nb::ndim<1>>>(disc.attr("C"));
            size_t n = Bd.shape(0);
            if (n > MAX_ORDER || Ad.shape(0) != n || Ad.shape(1) != n || C.shape(0) != n) {
                std::snprintf(message, size, "a discrete filter of %zu states (Ad %zu x %zu, C %zu), at most %d",
                              n, Ad.shape(0), Ad.shape(1), C.shape(0), MAX_ORDER);
                return -1;
            }
            out->n = static_cast<int>(n);
            std::memcpy(out->Ad, Ad.data(), n * n * sizeof(double));
            std::memcpy(out->Bd, Bd.data(), n * sizeof(double));
            std::memcpy(out->C, C.data(), n * sizeof(double));
            out->D = nb::cast<double>(disc.attr("D"));
            out->Ts = Ts;
            return 0;
        } catch (...) {
            self->error = std::current_exception();
            std::snprintf(message, size, "the discrete filter could not be made");
            return -1;
        }
    }
    // a refusal of the core, the Python error where the callable raised
    void check(int status, const char *message) const
    {
        if (status != 0 && error) std::rethrow_exception(error);
        ::check(status, message);
    }
};

// pickling (and copying) of a struct of plain data: its bytes
template <typename T> void plain_data(nb::class_<T> &cls)
{
    cls.def("__getstate__", [](const T &t) { return nb::bytes(reinterpret_cast<const char *>(&t), sizeof(T)); })
        .def("__setstate__", [](T &t, nb::bytes state) {
            if (state.size() != sizeof(T)) throw nb::value_error("a state of another build");
            new (&t) T;
            std::memcpy(static_cast<void *>(&t), state.c_str(), sizeof(T));
        });
}

void check_rows(size_t n, size_t rows, const char *name)
{
    if (rows != n)
        throw nb::value_error((std::string(name) + " has " + std::to_string(rows) + " rows, not " +
                               std::to_string(n)).c_str());
}

} // namespace

void bind_pipeline(nb::module_ &m)
{
    m.attr("MAX_GYR_RAD_S") = MAX_GYR_RAD_S;
    m.attr("MAX_ACC_M_S2") = MAX_ACC_M_S2;

    m.def("cpus", &cpus, "The CPUs this process may run on (its affinity on Linux), as the batch path counts them.");

    // ---- parameters
    m.def(
        "method_index", [](std::optional<std::string> name) { return method_of(name); }, "name"_a.none(),
        "The index of the method called name; ValueError naming the methods there are.");
    m.def(
        "resolve_params",
        [](const std::string &stage, nb::handle overrides) {
            char message[MESSAGE_SIZE];
            double resolved[AF_N_PARAMS];
            int index = stage_index(stage);
            Given given(overrides);
            check(resolve_given(index, given.data(), given.size(), resolved, message, sizeof message), message);
            return resolved_dict(index, resolved);
        },
        "stage"_a, "overrides"_a.none() = nb::none(),
        "The parameters of stage (a method's name, gyro_offset or heading): defaults (None where derived) "
        "updated by overrides (name -> value), as a dict in the stage's order; ValueError for an unknown name "
        "or a value out of range.");
    m.def(
        "split_params",
        [](std::optional<std::string> method, nb::handle params, bool offset, bool mag) {
            char message[MESSAGE_SIZE];
            AfGiven split[3][AF_N_PARAMS];
            int counts[3];
            int index = method_of(method);
            Given given(params);
            check(split_params(index, given.data(), given.size(), offset, mag, split[0], &counts[0], split[1],
                               &counts[1], split[2], &counts[2], message, sizeof message),
                  message);
            nb::dict out[3];
            for (int s = 0; s < 3; s++)
                for (int k = 0; k < counts[s]; k++) out[s][split[s][k].name] = given.value(split[s][k].name);
            return nb::make_tuple(out[0], out[1], out[2]);
        },
        "method"_a.none(), "params"_a.none(), "offset"_a, "mag"_a,
        "params (name -> value) split into the method's, the gyro-offset estimator's and the heading "
        "estimator's; ValueError for a name no running stage has.");
    m.def(
        "method_kernel",
        [](std::optional<std::string> method, nb::handle params) {
            char message[MESSAGE_SIZE];
            AfMethod config;
            Given given(params);
            check(method_configure(&config, method_of(method), given.data(), given.size(), message, sizeof message),
                  message);
            return std::string(KERNEL_NAMES[config.kernel]);
        },
        "method"_a.none(), "params"_a.none() = nb::none(),
        "What the method runs with these parameters: 'sensor_frame' (its earth filter) or its kernel's name; "
        "ValueError for parameters it refuses.");
    m.def(
        "wiener_local_coefficients",
        [](nb::dict params, double Ts) {
            double values[AF_N_PARAMS];
            WienerLocalCoef coef;
            resolved_values(params, values);
            wiener_local_coefficients(values, Ts, &coef);
            const double array[] = {coef.Ts, coef.g, coef.dn2, coef.k_w, coef.inv_J, coef.dv2_min, coef.a_avg,
                                    coef.leak_v};
            return array_of(array, {sizeof array / sizeof *array});
        },
        "params"_a, "Ts"_a,
        "[Ts, g, dn^2, k_w, 1/J, dv_min^2, a_avg, leak_v] of wiener's local densities for its resolved params.");

    // ---- samples and quaternions
    m.def(
        "valid_sample",
        [](Vec gyr, Vec acc) { return valid_sample(gyr.data(), acc.data()) != 0; }, "gyr"_a, "acc"_a,
        "Whether gyr (rad/s) and acc (m/s^2) are finite and within MAX_GYR_RAD_S, MAX_ACC_M_S2 per axis.");
    m.def(
        "start_gravity",
        [](Vec gyr0, Vec acc0, double Ts) {
            double out[3];
            start_gravity(gyr0.data(), acc0.data(), Ts, out);
            return array_of(out, {3});
        },
        "gyr0"_a, "acc0"_a, "Ts"_a);
    m.def(
        "attitude_error",
        [](Vec ghat, std::array<double, 4> q) { return attitude_error(ghat.data(), q.data()); }, "ghat"_a, "q"_a,
        "The inclination error (rad) between ghat (m/s^2, sensor coordinates) and the true up of q (sensor -> "
        "earth, [w, x, y, z]).");
    m.def(
        "integrate_rates",
        [](Rows3 gyr, double Ts, Out4 quat) {
            check_rows(gyr.shape(0), quat.shape(0), "quat");
            nb::gil_scoped_release released;
            integrate_rates(gyr.shape(0), gyr.data(), Ts, quat.data());
        },
        "gyr"_a, "Ts"_a, "quat"_a.noconvert(),
        "quat[k] (N x 4): the orientation after gyro sample k (N x 3 mean rates, rad/s, over Ts s each) from "
        "the identity before the first.");
    m.def(
        "euler_rates",
        [](Rows3 gyr, double Ts, double roll0, double pitch0) {
            size_t n = gyr.shape(0);
            std::vector<double> roll(n), pitch(n);
            euler_rates(n, gyr.data(), Ts, roll0, pitch0, roll.data(), pitch.data());
            return nb::make_tuple(array_of(roll.data(), {n}), array_of(pitch.data(), {n}));
        },
        "gyr"_a, "Ts"_a, "roll0"_a, "pitch0"_a,
        "(roll, pitch), rad, after each gyro sample, integrated through the Z-Y-X Euler kinematics.");
    m.def(
        "rest_state",
        [](In<double, nb::ndim<2>> Ad, In<double, nb::ndim<1>> Bd, Vec acc0) {
            DiscreteFilter d{};
            size_t n = Bd.shape(0);
            if (n > MAX_ORDER || Ad.shape(0) != n || Ad.shape(1) != n)
                throw nb::value_error("Ad must be n x n and Bd n, n at most MAX_ORDER");
            d.n = static_cast<int>(n);
            std::memcpy(d.Ad, Ad.data(), n * n * sizeof(double));
            std::memcpy(d.Bd, Bd.data(), n * sizeof(double));
            std::vector<double> X(3 * n + 1);
            rest_state(&d, acc0.data(), X.data());
            return array_of(X.data(), {n, 3});
        },
        "Ad"_a, "Bd"_a, "acc0"_a, "The state X (n x 3) a discrete filter holds after resting on acc0.");

    // ---- the methods' steppers
    nb::class_<AfStepper> stepper(m, "Stepper", "A method's step at one sample time (or any earth filter's "
                                                "sensor-frame step): its state is a float array.");
    stepper
        .def_static(
            "of_method",
            [](std::optional<std::string> method, nb::handle params, double Ts, nb::handle zoh) {
                char message[MESSAGE_SIZE];
                AfMethod config;
                AfStepper s;
                Given given(params);
                check(method_configure(&config, method_of(method), given.data(), given.size(), message,
                                       sizeof message),
                      message);
                PythonZoh hold(zoh);
                hold.check(stepper_at(&s, &config, Ts, &hold.zoh, message, sizeof message), message);
                return s;
            },
            "method"_a.none(), "params"_a.none(), "Ts"_a, "zoh"_a,
            "The method's step at Ts (s); zoh(Ts) gives the discrete filter of the earth filter it runs.")
        .def_static(
            "of_filter",
            [](In<double, nb::ndim<2>> Ad, In<double, nb::ndim<1>> Bd, In<double, nb::ndim<1>> C, double D,
               double Ts) {
                char message[MESSAGE_SIZE];
                DiscreteFilter d{};
                AfStepper s;
                size_t n = Bd.shape(0);
                if (Ad.shape(0) != n || Ad.shape(1) != n || C.shape(0) != n)
                    throw nb::value_error("Ad must be n x n, Bd and C n");
                d.n = static_cast<int>(n);
                d.D = D;
                d.Ts = Ts;
                if (n <= MAX_ORDER) {
                    std::memcpy(d.Ad, Ad.data(), n * n * sizeof(double));
                    std::memcpy(d.Bd, Bd.data(), n * sizeof(double));
                    std::memcpy(d.C, C.data(), n * sizeof(double));
                }
                check(stepper_of_filter(&s, &d, message, sizeof message), message);
                return s;
            },
            "Ad"_a, "Bd"_a, "C"_a, "D"_a, "Ts"_a, "The sensor-frame step of a discrete earth filter.")
        .def_prop_ro("state_names",
                     [](const AfStepper &s) {
                         char names[AF_STEPPER_STATE_MAX][STATE_NAME_SIZE];
                         stepper_state_names(&s, names);
                         return std::vector<std::string>(names, names + s.state_size);
                     })
        .def(
            "initial_state",
            [](const AfStepper &s, Vec gravity) {
                double state[AF_STEPPER_STATE_MAX];
                stepper_initial_state(&s, gravity.data(), state);
                return array_of(state, {static_cast<size_t>(s.state_size)});
            },
            "gravity"_a, "At rest on gravity (m/s^2, sensor coordinates).")
        .def(
            "run",
            [](const AfStepper &s, Out1 state, Rows3 gyr, Rows3 acc, Out3 gravity, Out4 quat) {
                size_t n = gyr.shape(0);
                if (state.shape(0) != static_cast<size_t>(s.state_size))
                    throw nb::value_error(("the state must have " + std::to_string(s.state_size) + " values").c_str());
                check_rows(n, acc.shape(0), "acc");
                check_rows(n, gravity.shape(0), "gravity");
                check_rows(n, quat.shape(0), "quat");
                nb::gil_scoped_release released;
                for (size_t k = 0; k < n; k++)
                    stepper_run(&s, state.data(), gyr.data() + 3 * k, acc.data() + 3 * k, gravity.data() + 3 * k,
                                quat.data() + 4 * k);
            },
            "state"_a.noconvert(), "gyr"_a, "acc"_a, "gravity"_a.noconvert(), "quat"_a.noconvert(),
            "Step over gyr (rad/s), acc (m/s^2), N x 3; state updated in place; gravity (N x 3, m/s^2) and "
            "quat (N x 4) written.");
    plain_data(stepper);

    // ---- the causal pipeline
    nb::class_<AfPipeline> pipeline(m, "Pipeline", "A configuration of the causal pipeline's stages, validated.");
    pipeline
        .def(
            "__init__",
            [](AfPipeline *self, std::optional<std::string> method, nb::handle params, bool gyro_offset,
               bool heading, double latency, const std::string &gyr_samples, const std::string &acc_samples) {
                char message[MESSAGE_SIZE];
                Given given(params);
                new (self) AfPipeline;
                check(causal_configure(self, optional_name(method), given.data(), given.size(), gyro_offset, heading,
                                       latency, gyr_samples.c_str(), acc_samples.c_str(), message, sizeof message),
                      message);
            },
            "method"_a.none(), "params"_a.none(), "gyro_offset"_a, "heading"_a, "latency"_a, "gyr_samples"_a,
            "acc_samples"_a)
        .def_prop_ro("latency", [](const AfPipeline &p) { return p.latency; })
        .def_prop_ro("point_gyr", [](const AfPipeline &p) { return p.point_gyr != 0; })
        .def_prop_ro("mean_acc", [](const AfPipeline &p) { return p.mean_acc != 0; })
        .def(
            "at",
            [](const AfPipeline &p, double Ts, nb::handle zoh) {
                char message[MESSAGE_SIZE];
                AfStep step;
                PythonZoh hold(zoh);
                hold.check(causal_at(&p, Ts, &hold.zoh, &step, message, sizeof message), message);
                return step;
            },
            "Ts"_a, "zoh"_a, "The pipeline discretised at Ts (s); zoh(Ts) gives the method's discrete filter.");
    plain_data(pipeline);

    nb::class_<AfStep> step(m, "Step", "The pipeline's coefficients at one sample time.");
    step.def_prop_ro("Ts", [](const AfStep &s) { return s.Ts; });
    plain_data(step);

    nb::class_<AfState> state(m, "State", "What the stages carry from one block of samples to the next.");
    state.def("__init__", [](AfState *self) {
        new (self) AfState;
        causal_initial_state(self);
    });
    plain_data(state);

    m.def(
        "run",
        [](const AfPipeline &p, const AfStep &step, AfState &state, Rows3 gyr, Rows3 acc, std::optional<Rows3> mag,
           std::optional<Vec> initial_gravity, Out3 gravity, Out4 quat, std::optional<Out3> offset,
           std::optional<Out3> offset_variance, std::optional<Out<bool, nb::shape<-1>>> mag_accepted,
           std::optional<Out3> mag_offset, std::optional<Out1> mag_delay, std::optional<int> threads,
           nb::object choose) {
            size_t n = gyr.shape(0);
            if (threads && *threads < 1)
                throw nb::value_error(("threads must be at least 1, got " + std::to_string(*threads)).c_str());
            check_rows(n, acc.shape(0), "acc");
            check_rows(n, gravity.shape(0), "gravity");
            check_rows(n, quat.shape(0), "quat");
            if (mag) check_rows(n, mag->shape(0), "mag");
            if (offset) check_rows(n, offset->shape(0), "offset");
            if (offset_variance) check_rows(n, offset_variance->shape(0), "offset_variance");
            if (mag_accepted) check_rows(n, mag_accepted->shape(0), "mag_accepted");
            if (mag_offset) check_rows(n, mag_offset->shape(0), "mag_offset");
            if (mag_delay) check_rows(n, mag_delay->shape(0), "mag_delay");
            static_assert(sizeof(bool) == sizeof(unsigned char), "numpy's bool is a byte");
            AfRows rows = {gravity.data(), quat.data(), offset ? offset->data() : nullptr,
                           offset_variance ? offset_variance->data() : nullptr,
                           mag_accepted ? reinterpret_cast<unsigned char *>(mag_accepted->data()) : nullptr,
                           mag_offset ? mag_offset->data() : nullptr, mag_delay ? mag_delay->data() : nullptr};
            const AfInputs in = {gyr.data(), acc.data(), mag ? mag->data() : nullptr,
                                 initial_gravity ? initial_gravity->data() : nullptr};
            Choice chooser;
            if (!choose.is_none())
                chooser = [&choose, &step, &p](AfStep &chosen, int workers) {
                    nb::gil_scoped_acquire locked;
                    nb::object made = choose(workers);
                    if (made.is_none()) return;
                    const AfStep &s = nb::cast<const AfStep &>(made);
                    if (s.Ts != step.Ts || s.stepper.kernel != step.stepper.kernel ||
                        s.stepper.state_size != step.stepper.state_size ||
                        (p.offset_runs && std::memcmp(&s.offset_coef, &step.offset_coef, sizeof s.offset_coef) != 0))
                        throw nb::value_error("the chosen step must differ in the method's and the heading's "
                                              "coefficients alone");
                    chosen.stepper = s.stepper;
                    chosen.heading_coef = s.heading_coef;
                };
            nb::gil_scoped_release released;
            pipelined_run(p, step, state, n, in, rows, threads.value_or(0), chooser);
        },
        "pipeline"_a, "step"_a, "state"_a, "gyr"_a, "acc"_a, "mag"_a.none(), "initial_gravity"_a.none(),
        "gravity"_a.noconvert(), "quat"_a.noconvert(), "offset"_a.noconvert().none(),
        "offset_variance"_a.noconvert().none(), "mag_accepted"_a.noconvert().none(),
        "mag_offset"_a.noconvert().none(), "mag_delay"_a.noconvert().none(), "threads"_a.none() = nb::none(),
        "choose"_a.none() = nb::none(),
        "The rows gyr (N x 3, rad/s), acc (N x 3, m/s^2) and mag (N x 3, uT, or None) through the pipeline's "
        "stages, state carried on; the outputs written into the arrays given (None: not wanted). threads: at "
        "most this many (the stages split over two at most; the outputs are the same on any number); None: two "
        "from 20 000 rows on where the process may run on two CPUs or more. choose (None: none): "
        "choose(threads) gives the Step to run the method and the heading with (None: step), made before the "
        "method's first row with up to that many threads; on two threads while the first runs the timing and "
        "gyro-offset stages ahead.");

    m.def(
        "smooth",
        [](const AfStep &step, Rows3 gyr, Rows3 acc, std::optional<Vec> initial_gravity, Out3 gravity, Out4 quat) {
            size_t n = gyr.shape(0);
            if (n == 0) throw nb::value_error("no samples to smooth");
            check_rows(n, acc.shape(0), "acc");
            check_rows(n, gravity.shape(0), "gravity");
            check_rows(n, quat.shape(0), "quat");
            double start[3];
            if (initial_gravity)
                std::memcpy(start, initial_gravity->data(), sizeof start);
            else
                start_gravity(gyr.data(), acc.data(), step.Ts, start);
            std::vector<double> omega(n);
            nb::gil_scoped_release released;
            offline_smooth(&step.stepper, n, gyr.data(), acc.data(), start, gravity.data(), quat.data(), omega.data());
        },
        "step"_a, "gyr"_a, "acc"_a, "initial_gravity"_a.none(), "gravity"_a.noconvert(), "quat"_a.noconvert(),
        "The offline smoother of the step's method over gyr, acc (N x 3): gravity (N x 3) and quat (N x 4) "
        "written; it starts at rest on initial_gravity, None: start_gravity of the first sample.");

    m.def(
        "scale_error_errors",
        [](const AfStep &warm, const std::vector<AfStep> &candidates, Rows3 gyr, Rows3 acc, size_t warm_up,
           std::optional<Vec> initial_gravity, size_t horizon, size_t block) {
            size_t n = gyr.shape(0), count = candidates.size();
            check_rows(n, acc.shape(0), "acc");
            if (count < 1 || count > PREDICTION_MAX_COUNT)
                throw nb::value_error(("1 to " + std::to_string(PREDICTION_MAX_COUNT) + " candidates, got " +
                                       std::to_string(count)).c_str());
            const WienerLocalCoef &w = warm.stepper.coef.wiener_local;
            auto coef_of = [&w](const AfStep &step) {
                const WienerLocalCoef &c = step.stepper.coef.wiener_local;
                if (step.stepper.kernel != KERNEL_WIENER_LOCAL)
                    throw nb::value_error("scale_error_errors scores the Wiener filter with local densities alone");
                if (c.Ts != w.Ts || c.a_avg != w.a_avg || c.leak_v != w.leak_v)
                    throw nb::value_error("the candidates must share the sample time, tau_noise and tau_v");
                return c;
            };
            coef_of(warm);
            std::vector<WienerLocalCoef> coefs;
            for (const AfStep &step : candidates) coefs.push_back(coef_of(step));
            if (warm_up > n) throw nb::value_error("the warm-up is longer than the window");
            if (horizon < 1 || block < 1) throw nb::value_error("horizon and block must be 1 sample or more");
            size_t first = warm_up >= horizon ? warm_up - horizon : 0;
            size_t per = n - first > horizon ? (n - first - horizon + block - 1) / block : 0;
            double start[3];
            if (initial_gravity)
                std::memcpy(start, initial_gravity->data(), sizeof start);
            else if (n > 0)
                start_gravity(gyr.data(), acc.data(), w.Ts, start);
            std::vector<double> gravity(3 * n * count), work(3 * horizon * count), means(count * per);
            if (per > 0) {
                nb::gil_scoped_release released;
                scale_error_errors(&w, coefs.data(), count, n, warm_up, gyr.data(), acc.data(), start, horizon, block,
                                   gravity.data(), work.data(), means.data());
            }
            return array_of(means.data(), {count, per});
        },
        "warm"_a, "candidates"_a, "gyr"_a, "acc"_a, "warm_up"_a, "initial_gravity"_a.none(), "horizon"_a, "block"_a,
        "The candidates' (Steps of the Wiener filter with local densities alone) block means of the prediction "
        "error (m^2/s^4) over a window of gyr (rad/s) and acc (m/s^2), N x 3: each starts at rest on "
        "initial_gravity (None: start_gravity of the first sample), runs warm_up rows with warm, then on with "
        "its own (blocks/core/stages/scale_error.h); an array of one row per candidate.");

    // ---- the online estimator
    nb::class_<AfOnline> online(m, "Online", "The causal pipeline one sample at a time.");
    online.def("__init__", [](AfOnline *self, const AfPipeline &p) { af_online_of(new (self) AfOnline, &p); },
               "pipeline"_a)
        .def("reset", [](AfOnline &est) { af_online_reset(&est); }, "Forget every sample.")
        .def(
            "step",
            [](AfOnline &est, Vec gyr, Vec acc, double Ts, Vec mag, nb::handle zoh) {
                char message[MESSAGE_SIZE];
                PythonZoh hold(zoh);
                int taken = af_online_step_with(&est, gyr.data(), acc.data(), mag.data(), Ts, &hold.zoh, message,
                                                sizeof message);
                hold.check(taken < 0, message);
                return taken == 1;
            },
            "gyr"_a, "acc"_a, "Ts"_a, "mag"_a, "zoh"_a,
            "Take one sample; whether it was taken. zoh(Ts) gives the method's discrete filter at a new Ts.")
        .def_prop_ro("started", [](const AfOnline &est) { return est.state.started != 0; })
        .def_prop_ro("quat", [](const AfOnline &est) { return array_of(est.quat, {4}); }, nb::rv_policy::move)
        .def_prop_ro("up", [](const AfOnline &est) { return array_of(est.up, {3}); }, nb::rv_policy::move)
        .def_prop_ro("euler", [](const AfOnline &est) { return array_of(est.euler, {3}); }, nb::rv_policy::move)
        .def_prop_ro("offset", [](const AfOnline &est) { return array_of(est.offset, {3}); }, nb::rv_policy::move)
        .def_prop_ro("mag_offset", [](const AfOnline &est) { return array_of(est.mag_offset, {3}); }, nb::rv_policy::move)
        .def_prop_ro("mag_delay", [](const AfOnline &est) { return est.mag_delay; });
    plain_data(online);
}

// simulation.cpp: the simulation's C core (systems/simulation/core) bound into attitude_fmu._core:
// the noise streams, HumanMotion, the closed-form profiles, the earth's field, the IMU sensor
// model and its delay line. Loops over arrays of samples take preallocated C-contiguous float64 arrays (one call per
// stream); every count, width and length from Python is checked here before the C core sees it.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cstring>
#include <memory>
#include <new>
#include <string>

extern "C" {
#include "closed_form.h"
#include "delay_line.h"
#include "earth_field.h"
#include "human_motion.h"
#include "noise.h"
#include "profile_params.h"
#include "sensor.h"
}

namespace nb = nanobind;

namespace {

constexpr size_t MESSAGE_SIZE = 512;

template <ssize_t... Shape>
using In = nb::ndarray<const double, nb::shape<Shape...>, nb::c_contig, nb::device::cpu>;
template <ssize_t... Shape>
using Out = nb::ndarray<double, nb::shape<Shape...>, nb::c_contig, nb::device::cpu>;
using Vector = nb::ndarray<nb::numpy, double, nb::ndim<1>>;

// a new numpy vector of n floats
Vector new_vector(size_t n)
{
    double *data = new double[n];
    nb::capsule owner(data, [](void *p) noexcept { delete[] static_cast<double *>(p); });
    return Vector(data, {n}, owner);
}

// ValueError where a C check refused (status -1 with its message)
void raise_if(int status, const char *message)
{
    if (status != 0) throw nb::value_error(message);
}

void same_rows(size_t a, size_t b, const char *what)
{
    if (a != b) throw nb::value_error((std::string(what) + " must have the same number of rows").c_str());
}

// seed as a seed: a whole number (numbers.Integral, not bool) in [0, 2**64), else ValueError with
// noise.c's refusal
uint64_t seed_value(nb::handle seed)
{
    nb::object integral = nb::module_::import_("numbers").attr("Integral");
    int whole = PyBool_Check(seed.ptr()) ? 0 : PyObject_IsInstance(seed.ptr(), integral.ptr());
    if (whole == 1) {
        nb::object value = nb::steal(PyNumber_Long(seed.ptr()));
        if (value.is_valid()) {
            unsigned long long v = PyLong_AsUnsignedLongLong(value.ptr());
            if (!(v == static_cast<unsigned long long>(-1) && PyErr_Occurred())) return v;
        }
    }
    PyErr_Clear();
    char message[MESSAGE_SIZE];
    refuse_seed(nb::repr(seed).c_str(), message, sizeof message);
    throw nb::value_error(message);
}

// the profile's parameters (n, profile_table.py's order) and g checked (profile_params.h): ValueError with the
// refusal, or for a name that is no profile
void check_profile(const std::string &name, const double *values, size_t n, double g)
{
    const SimProfile *profile = profile_named(name.c_str());
    if (profile == nullptr) throw nb::value_error(("no motion profile " + name).c_str());
    char message[MESSAGE_SIZE];
    raise_if(profile_check(profile, values, n, g, message, sizeof message), message);
}

// the human motion's parameters, its grid (s) and its lever arm (m), checked
HumanParams human_params(double delta_v, double omega_c, double rot_rms, double rot_cutoff, double grid, double g,
                         In<3> lever)
{
    const double *r = lever.data();
    const double values[8] = {delta_v, omega_c, rot_rms, rot_cutoff, grid, r[0], r[1], r[2]};
    check_profile("human", values, 8, g);
    return HumanParams{delta_v, omega_c, rot_rms, rot_cutoff, g, {r[0], r[1], r[2]}};
}

// the stream's (start, end] as (gyr, specific force, quat), else ValueError
nb::tuple stream_step(HumanStream &s, double start, double end)
{
    double out[HUMAN_N_OUT];
    char message[MESSAGE_SIZE];
    raise_if(human_stream_step(&s, start, end, out, message, sizeof message), message);
    Vector gyr = new_vector(3), f = new_vector(3), quat = new_vector(4);
    std::memcpy(gyr.data(), out, 3 * sizeof(double));
    std::memcpy(f.data(), out + 3, 3 * sizeof(double));
    std::memcpy(quat.data(), out + 6, 4 * sizeof(double));
    return nb::make_tuple(gyr, f, quat);
}

// ImuModel.vector (sensor.h, imu_from_vector), checked
using ImuVector = In<IMU_VECTOR_SIZE>;

ImuParams imu_params(const ImuVector &v)
{
    ImuParams p;
    char message[MESSAGE_SIZE];
    raise_if(imu_from_vector(v.data(), &p, message, sizeof message), message);
    return p;
}

// a delay line (on the heap: it is large) at fs for latency, every past row equal to before
std::unique_ptr<DelayLine> delay_line(double latency, double fs, const double before[DELAY_WIDTH])
{
    std::unique_ptr<DelayLine> line(new DelayLine);
    char message[MESSAGE_SIZE];
    raise_if(delay_init(line.get(), latency, fs, before, message, sizeof message), message);
    return line;
}

size_t past_size(const DelayLine &line) { return static_cast<size_t>(line.rows - 1) * DELAY_WIDTH; }

void bind_noise(nb::module_ &m)
{
    m.attr("MOTION") = static_cast<int>(MOTION);
    m.attr("SENSOR") = static_cast<int>(SENSOR);
    m.attr("MAGNETOMETER") = static_cast<int>(MAGNETOMETER);
    m.attr("MOTION_WIDTH") = MOTION_WIDTH;
    m.attr("SENSOR_WIDTH") = SENSOR_WIDTH;
    m.attr("MAGNETOMETER_WIDTH") = MAGNETOMETER_WIDTH;

    m.def("check_seed", [](nb::handle seed) { return seed_value(seed); }, nb::arg("seed"),
          "seed as an int, or ValueError: a whole number in [0, 2**64).");
    m.def(
        "philox4x64",
        [](uint64_t c0, uint64_t c1, uint64_t c2, uint64_t c3, uint64_t k0, uint64_t k1) {
            const uint64_t c[4] = {c0, c1, c2, c3}, k[2] = {k0, k1};
            uint64_t w[4];
            philox4x64(c, k, w);
            return nb::make_tuple(w[0], w[1], w[2], w[3]);
        },
        nb::arg("c0"), nb::arg("c1"), nb::arg("c2"), nb::arg("c3"), nb::arg("k0"), nb::arg("k1"),
        "The Philox4x64-10 block (4 words) of counter (c0, c1, c2, c3) under key (k0, k1).");
    m.def(
        "normals",
        [](nb::handle seed, uint64_t stream, uint64_t first, Out<-1, -1> out) {
            uint64_t s = seed_value(seed);
            noise_fill(s, stream, first, out.shape(0), out.shape(1), out.data());
        },
        nb::arg("seed"), nb::arg("stream"), nb::arg("first"), nb::arg("out").noconvert(),
        "Fill out (n x width) with the unit normals of samples first ... first + n - 1 of a stream under seed.");
}

void bind_human_motion(nb::module_ &m)
{
    m.attr("HUMAN_N_STATES") = HUMAN_N_STATES;
    m.attr("HUMAN_N_OUT") = HUMAN_N_OUT;
    m.def(
        "profile_check",
        [](const std::string &name, In<-1> values, double g) { check_profile(name, values.data(), values.shape(0), g); },
        nb::arg("name"), nb::arg("values"), nb::arg("g"),
        "A motion profile's parameters (profile_table.py's order) and gravity g (m/s^2) within their plausible "
        "ranges (profile_table.py's): ValueError naming the parameter, its value and the range.");
    m.def(
        "human_coefficients",
        [](double delta_v, double omega_c, double rot_rms, double rot_cutoff, double g, In<3> lever, double fs) {
            const double *r = lever.data();
            HumanParams p = {delta_v, omega_c, rot_rms, rot_cutoff, g, {r[0], r[1], r[2]}};
            Vector coef = new_vector(HUMAN_N_COEF);
            human_coefficients(&p, fs, coef.data());
            return coef;
        },
        nb::arg("delta_v"), nb::arg("omega_c"), nb::arg("rot_rms"), nb::arg("rot_cutoff"), nb::arg("g"),
        nb::arg("lever"), nb::arg("fs"),
        "[phi_v, sig_v, phi_w, sig_w, Ts, g, lever (3)]: the exact steps' coefficients at fs (Hz).");
    m.def(
        "human_run",
        [](Out<HUMAN_N_STATES> state, In<-1, 6> noise, In<HUMAN_N_COEF> coef, Out<-1, HUMAN_N_OUT> out) {
            same_rows(noise.shape(0), out.shape(0), "noise and out");
            human_run(state.data(), noise.data(), noise.shape(0), coef.data(), out.data());
        },
        nb::arg("state").noconvert(), nb::arg("noise"), nb::arg("coef"), nb::arg("out").noconvert(),
        "n samples from n rows of unit normals: state (10: v, omega, q) advanced in place, out (n x 10: "
        "omega, specific force, q).");

    nb::class_<HumanStream>(m, "HumanStream", "HumanMotion on its time grid from a seed (its noise stream "
                                              "MOTION), over any intervals of time from 0.")
        .def(
            "__init__",
            [](HumanStream *s, double delta_v, double omega_c, double rot_rms, double rot_cutoff, double grid,
               In<3> lever, double g, nb::handle seed) {
                HumanParams p = human_params(delta_v, omega_c, rot_rms, rot_cutoff, grid, g, lever);
                uint64_t value = seed_value(seed);
                new (s) HumanStream;
                human_stream_init(s, &p, grid, value);
            },
            nb::arg("delta_v"), nb::arg("omega_c"), nb::arg("rot_rms"), nb::arg("rot_cutoff"), nb::arg("grid"),
            nb::arg("lever"), nb::arg("g"), nb::arg("seed"))
        .def(
            "step", [](HumanStream &s, double t, double h) { return stream_step(s, t - h, t); }, nb::arg("t"),
            nb::arg("h"), "Ideal (gyr, specific force, quat) for the interval (t - h, t] (s).")
        .def(
            "run",
            [](HumanStream &s, In<-1> t, Out<-1, HUMAN_N_OUT> out) {
                same_rows(t.shape(0), out.shape(0), "t and out");
                char message[MESSAGE_SIZE];
                double start = s.t;
                for (size_t k = 0; k < t.shape(0); k++) {
                    raise_if(human_stream_step(&s, start, t.data()[k], out.data() + HUMAN_N_OUT * k, message,
                                               sizeof message),
                             message);
                    start = t.data()[k];
                }
            },
            nb::arg("t"), nb::arg("out").noconvert(),
            "The intervals from the last one's end to t[0], then (t[k-1], t[k]]: out (n x 10: gyr, specific "
            "force, quat).")
        .def_prop_ro("k", [](const HumanStream &s) { return s.k; }, "grid cells drawn")
        .def("__getstate__",
             [](const HumanStream &s) { return nb::bytes(reinterpret_cast<const char *>(&s), sizeof s); })
        .def("__setstate__", [](HumanStream &s, nb::bytes state) {
            if (state.size() != sizeof(HumanStream)) throw nb::value_error("not the state of a HumanStream");
            HumanStream restored;
            std::memcpy(&restored, state.c_str(), sizeof restored);
            const HumanParams &p = restored.params;
            const double values[8] = {p.delta_v, p.omega_c, p.rot_rms, p.rot_cutoff, restored.grid,
                                      p.lever[0], p.lever[1], p.lever[2]};
            check_profile("human", values, 8, p.g);
            new (&s) HumanStream(restored);
        });
}

void bind_closed_form(nb::module_ &m)
{
    nb::list names;
    for (int profile = 0; profile < N_CLOSED_FORMS; profile++) names.append(CLOSED_FORM_NAMES[profile]);
    m.attr("CLOSED_FORMS") = nb::tuple(names);
    m.def(
        "closed_form_run",
        [](const std::string &name, In<-1> params, double g, In<-1> t, double h, Out<-1, 3> gyr, Out<-1, 3> f,
           Out<-1, 4> quat) {
            ClosedForm motion = {};
            int profile = closed_form_profile(name.c_str());
            if (profile < 0) throw nb::value_error(("no closed form " + name).c_str());
            if (params.shape(0) > CLOSED_FORM_MAX_PARAMS)
                throw nb::value_error(("too many parameters for the closed form " + name).c_str());
            motion.profile = static_cast<ClosedFormProfile>(profile);
            std::memcpy(motion.p, params.data(), params.shape(0) * sizeof(double));
            motion.g = g;
            size_t n = t.shape(0);
            same_rows(n, gyr.shape(0), "t and gyr");
            same_rows(n, f.shape(0), "t and f");
            same_rows(n, quat.shape(0), "t and quat");
            closed_form_run(&motion, t.data(), n, h, gyr.data(), f.data(), quat.data());
        },
        nb::arg("name"), nb::arg("params"), nb::arg("g"), nb::arg("t"), nb::arg("h"), nb::arg("gyr").noconvert(),
        nb::arg("f").noconvert(), nb::arg("quat").noconvert(),
        "The closed-form profile name (CLOSED_FORMS) with its parameters (profile_table.py's order) and "
        "gravity g over the intervals (t - h, t] ending at the times t (n): gyr, specific force f (n x 3), "
        "quat (n x 4).");
}

void bind_earth_field(nb::module_ &m)
{
    m.def(
        "earth_field",
        [](In<-1, 4> quat, Out<-1, 3> out) {
            same_rows(quat.shape(0), out.shape(0), "quat and out");
            earth_field_run(quat.data(), quat.shape(0), out.data());
        },
        nb::arg("quat"), nb::arg("out").noconvert(),
        "The earth's field (uT, EARTH_FIELD_UT in ENU) in the coordinates of sensors at the orientations quat "
        "(n x 4, sensor -> earth) into out (n x 3).");
}

void bind_sensor(nb::module_ &m)
{
    m.attr("IMU_N_PARAMS") = IMU_VECTOR_SIZE;
    m.def("imu_check", [](ImuVector params) { imu_params(params); }, nb::arg("params"),
          "ImuModel's refusals (params: ImuModel.vector): ValueError with the reason.");
    m.def(
        "imu_refuse_vector",
        [](const std::string &name, nb::handle value) {
            char message[MESSAGE_SIZE];
            imu_refuse_vector(name.c_str(), nb::repr(value).c_str(), message, sizeof message);
            throw nb::value_error(message);
        },
        nb::arg("name"), nb::arg("value"),
        "ValueError: the vector parameter name (gyr_offset, acc_offset, mag_offset, gyr_scale, mag_soft_iron) is not "
        "finite numbers of its shape, given value.");
    m.def(
        "imu_measure",
        [](ImuVector params, double fs, In<-1, 3> omega, In<-1, 3> f, In<-1, 6> noise, Out<-1, 3> gyr,
           Out<-1, 3> acc) {
            ImuParams p = imu_params(params);
            size_t n = omega.shape(0);
            same_rows(n, f.shape(0), "omega and f");
            same_rows(n, noise.shape(0), "omega and noise");
            same_rows(n, gyr.shape(0), "omega and gyr");
            same_rows(n, acc.shape(0), "omega and acc");
            imu_measure_run(&p, omega.data(), f.data(), noise.data(), n, fs, gyr.data(), acc.data());
        },
        nb::arg("params"), nb::arg("fs"), nb::arg("omega"), nb::arg("f"), nb::arg("noise"),
        nb::arg("gyr").noconvert(), nb::arg("acc").noconvert(),
        "Measured gyr, acc (n x 3) from the true rate omega, specific force f (n x 3) and unit normals "
        "(n x 6: gyro, then accelerometer) at fs (Hz).");
    m.def(
        "imu_measure_mag",
        [](ImuVector params, double fs, In<-1, 3> field, In<-1, 3> noise, Out<-1, 3> mag) {
            ImuParams p = imu_params(params);
            size_t n = field.shape(0);
            same_rows(n, noise.shape(0), "m and noise");
            same_rows(n, mag.shape(0), "m and mag");
            imu_measure_mag_run(&p, field.data(), noise.data(), n, fs, mag.data());
        },
        nb::arg("params"), nb::arg("fs"), nb::arg("m"), nb::arg("noise"), nb::arg("mag").noconvert(),
        "Measured field mag (n x 3, uT) from the true field m (n x 3, uT, sensor coordinates) and unit "
        "normals (n x 3) at fs (Hz).");

    m.def(
        "delay_run",
        [](double latency, double fs, In<DELAY_WIDTH> before, In<-1, DELAY_WIDTH> signals,
           Out<-1, DELAY_WIDTH> out) {
            same_rows(signals.shape(0), out.shape(0), "signals and out");
            std::unique_ptr<DelayLine> line = delay_line(latency, fs, before.data());
            delay_run(line.get(), signals.data(), signals.shape(0), out.data());
        },
        nb::arg("latency"), nb::arg("fs"), nb::arg("before"), nb::arg("signals"), nb::arg("out").noconvert(),
        "The true (omega, f) rows (n x 6) latency (s) ago at fs (Hz) into out (may be signals), the motion "
        "before the first sample taken as before (6).");
    m.def(
        "delay_state",
        [](double latency, double fs, In<DELAY_WIDTH> before) {
            std::unique_ptr<DelayLine> line = delay_line(latency, fs, before.data());
            Vector past = new_vector(past_size(*line));
            delay_save(line.get(), past.data());
            return past;
        },
        nb::arg("latency"), nb::arg("fs"), nb::arg("before"),
        "The delay line's state before the first sample: its past (omega, f) rows, newest first, all "
        "equal to before (6).");
    m.def(
        "delay_step",
        [](double latency, double fs, In<-1> past, In<DELAY_WIDTH> signals) {
            const double zeros[DELAY_WIDTH] = {0.0};
            std::unique_ptr<DelayLine> line = delay_line(latency, fs, zeros);
            if (past.shape(0) != past_size(*line))
                throw nb::value_error(("the delay line's state holds " + std::to_string(past_size(*line)) +
                                       " numbers at this latency and rate, got " + std::to_string(past.shape(0)))
                                          .c_str());
            delay_load(line.get(), past.data());
            Vector out = new_vector(DELAY_WIDTH), next = new_vector(past_size(*line));
            delay_step(line.get(), signals.data(), out.data());
            delay_save(line.get(), next.data());
            return nb::make_tuple(next, out);
        },
        nb::arg("latency"), nb::arg("fs"), nb::arg("past"), nb::arg("signals"),
        "(next state, the (omega, f) latency seconds ago) for this sample's true (omega, f) (6).");
}

} // namespace

void bind_simulation(nb::module_ &m)
{
    bind_noise(m);
    bind_human_motion(m);
    bind_closed_form(m);
    bind_earth_field(m);
    bind_sensor(m);
}

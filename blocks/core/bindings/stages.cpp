// stages.cpp: the estimator's stages bound into attitude_fmu._core (nanobind): the gyro-offset
// estimator, heading with its hard-iron fit and magnetometer delay, sample timing and latency,
// and the delay measurement's per-span kernel (their parameters: _core.resolve_params, pipeline.cpp).
// States and coefficients are float64 arrays the caller keeps; every array loop runs one
// recording per call. Python's documentation of each: blocks/stages/*.py.
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

extern "C" {
#include "messages.h"
#include "params.h"
#include "stages/delays.h"
#include "stages/gyro_offset.h"
#include "stages/heading.h"
#include "stages/lever_arm.h"
#include "pipeline/offline.h"
#include "stages/prediction.h"
#include "stages/timing.h"
}

namespace nb = nanobind;

namespace {

using Vector = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Rows3 = nb::ndarray<double, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu>;
using Rows4 = nb::ndarray<double, nb::shape<-1, 4>, nb::c_contig, nb::device::cpu>;
using Flags = nb::ndarray<bool, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Three = nb::ndarray<const double, nb::shape<3>, nb::c_contig, nb::device::cpu>;

constexpr size_t MESSAGE_SIZE = 2048;

/* a new float64 array of n entries */
nb::ndarray<nb::numpy, double, nb::ndim<1>> new_vector(size_t n)
{
    double *data = new double[n];
    nb::capsule owner(data, [](void *p) noexcept { delete[] static_cast<double *>(p); });
    return nb::ndarray<nb::numpy, double, nb::ndim<1>>(data, {n}, owner);
}

/* the number of doubles of a struct of doubles (a stage's state or coefficients) */
template <typename T> constexpr size_t doubles()
{
    return sizeof(T) / sizeof(double);
}

/* a vector of doubles as the struct of doubles it holds (a stage's state or coefficients) */
template <typename T, typename Array> T *as(const Array &a, const char *what)
{
    if (a.shape(0) != doubles<T>())
        throw nb::value_error((std::string(what) + " must hold " + std::to_string(doubles<T>()) + " values, got " +
                               std::to_string(a.shape(0)))
                                  .c_str());
    return reinterpret_cast<T *>(a.data());
}

void check_rows(size_t rows, size_t n, const char *what)
{
    if (rows != n)
        throw nb::value_error((std::string(what) + " has " + std::to_string(rows) + " rows, not " + std::to_string(n))
                                  .c_str());
}

/* the heading stage's rows: quat's count, which mag, out, accepted, offset and delay must have */
size_t heading_rows(const Rows4 &quat, const Rows3 &mag, const Rows4 &out, const Flags &accepted, const Rows3 &offset,
                    const Vector &delay)
{
    size_t n = quat.shape(0);
    check_rows(mag.shape(0), n, "mag");
    check_rows(out.shape(0), n, "out");
    check_rows(accepted.shape(0), n, "accepted");
    check_rows(offset.shape(0), n, "offset");
    check_rows(delay.shape(0), n, "delay");
    return n;
}

/* text with its first occurrence of from replaced by to */
std::string replaced(std::string text, const std::string &from, const std::string &to)
{
    size_t at = text.find(from);
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

/* a stage's parameters (a dict name -> value, None: the default, as _core.resolve_params gives
 * them) resolved into AF_N_PARAMS values; ValueError where resolve_params refuses them */
void resolved_params(int stage, nb::handle params, double resolved[AF_N_PARAMS])
{
    double given[AF_N_PARAMS];
    char message[MESSAGE_SIZE];
    for (int i = 0; i < AF_N_PARAMS; i++) given[i] = NAN;
    if (!params.is_none())
        for (nb::handle item : params.attr("items")()) {
            std::string name = nb::cast<std::string>(nb::str(item[0]));
            int index = param_index(name.c_str());
            if (index < 0 || stage_param(stage, index) == NULL)
                throw nb::value_error((AF_STAGES[stage].owner + std::string(" has no parameter ") + name).c_str());
            if (!item[1].is_none()) given[index] = nb::cast<double>(item[1]);
        }
    if (resolve_params(stage, given, resolved, message, sizeof message)) throw nb::value_error(message);
}

/* a sample time Ts (s): ValueError unless finite and positive (worded as causal_at words it) */
void check_step(double Ts)
{
    char message[MESSAGE_SIZE], text[FLOAT_REPR_SIZE];
    if (!(std::isfinite(Ts) && Ts > 0)) {
        snprintf(message, sizeof message, "sample time must be a finite positive number of seconds, got %s",
                 float_repr(Ts, text));
        throw nb::value_error(message);
    }
}

/* the names of a struct's entries (a python-control block's state names), from the table of its
 * fields, appended to out: a field's name for one entry, with _x, _y, _z for three and _w ... _z
 * for four, else _0, _1, ... */
void add_names(nb::list &out, const AfField *fields, size_t n_fields, const char *prefix = "")
{
    static const char *const xyz[] = {"x", "y", "z"}, *const wxyz[] = {"w", "x", "y", "z"};
    for (size_t f = 0; f < n_fields; f++) {
        std::string name = prefix + std::string(fields[f].name);
        for (size_t i = 0; i < fields[f].count; i++) {
            size_t count = fields[f].count;
            out.append(count == 1   ? name
                       : count == 3 ? name + "_" + xyz[i]
                       : count == 4 ? name + "_" + wxyz[i]
                                    : name + "_" + std::to_string(i));
        }
    }
}

/* names as a tuple, which must name each of a state's doubles */
nb::tuple state_names(const nb::list &names, size_t doubles)
{
    if (names.size() != doubles) throw std::logic_error("a state's fields do not cover it");
    return nb::tuple(names);
}

/* the coefficients of a stage at Ts: ValueError where they overflow */
void check_coefficients(int status, int stage, double Ts)
{
    char message[MESSAGE_SIZE];
    if (status != 0) {
        snprintf(message, sizeof message, "%s at Ts = %g s: its coefficients overflow", AF_STAGES[stage].owner, Ts);
        throw nb::value_error(message);
    }
}

} // namespace

void bind_stages(nb::module_ &m)
{
    // ---- the gyro-offset estimator
    nb::list offset_names;
    add_names(offset_names, GYRO_OFFSET_STATE_FIELDS, GYRO_OFFSET_N_FIELDS);
    m.attr("GYRO_OFFSET_STATE_NAMES") = state_names(offset_names, doubles<AfGyroOffset>());
    m.def("gyro_offset_coefficients", [](nb::handle params, double Ts) {
        double resolved[AF_N_PARAMS];
        resolved_params(AF_STAGE_gyro_offset, params, resolved);
        check_step(Ts);
        auto coef = new_vector(doubles<AfGyroOffsetCoef>());
        check_coefficients(gyro_offset_coefficients(resolved, Ts, as<AfGyroOffsetCoef>(coef, "coef")),
                           AF_STAGE_gyro_offset, Ts);
        return coef;
    }, nb::arg("params").none(), nb::arg("Ts"),
          "The estimator's coefficients at the sample time Ts (s) from its parameters (None: unset).");
    m.def("gyro_offset_initial_state", [](const Vector &coef, const Three &gyr0, const Three &acc0) {
        auto state = new_vector(doubles<AfGyroOffset>());
        gyro_offset_initial_state(as<AfGyroOffsetCoef>(coef, "coef"), gyr0.data(), acc0.data(),
                                  as<AfGyroOffset>(state, "state"));
        return state;
    }, nb::arg("coef"), nb::arg("gyr0"), nb::arg("acc0"),
          "The state on the first samples gyr0 (rad/s) and acc0 (m/s²): at rest, no offset.");
    m.def("gyro_offset_run", [](Vector state, const Vector &coef, const Rows3 &gyr, const Rows3 &acc, Rows3 offset,
                                Rows3 variance, std::optional<Flags> allowed, std::optional<Flags> resting,
                                std::optional<Rows3> acc_out) {
        AfGyroOffset *s = as<AfGyroOffset>(state, "state");
        const AfGyroOffsetCoef *c = as<AfGyroOffsetCoef>(coef, "coef");
        size_t n = gyr.shape(0);
        check_rows(acc.shape(0), n, "acc");
        check_rows(offset.shape(0), n, "offset");
        check_rows(variance.shape(0), n, "variance");
        if (allowed) check_rows(allowed->shape(0), n, "allowed");
        if (resting) check_rows(resting->shape(0), n, "resting");
        if (acc_out) check_rows(acc_out->shape(0), n, "acc_out");
        auto flags = [](std::optional<Flags> &f) {
            return f ? reinterpret_cast<unsigned char *>(f->data()) : nullptr;
        };
        nb::gil_scoped_release unlocked;
        gyro_offset_run(s, c, n, gyr.data(), acc.data(), flags(allowed), offset.data(), variance.data(),
                        acc_out ? acc_out->data() : nullptr, flags(resting));
    }, nb::arg("state").noconvert(), nb::arg("coef"), nb::arg("gyr"), nb::arg("acc"), nb::arg("offset").noconvert(),
          nb::arg("variance").noconvert(), nb::arg("allowed").none() = nb::none(),
          nb::arg("resting").noconvert().none() = nb::none(), nb::arg("acc_out").noconvert().none() = nb::none(),
          "Over N samples gyr (N×3, rad/s), acc (N×3, m/s²): the offset estimate after each (N×3, rad/s)\n"
          "and its variance per axis (N×3, (rad/s)²) into offset and variance; state in place. allowed (N\n"
          "flags; None: all): a sample at rest measures the offset only where set; resting (N flags, None:\n"
          "not wanted): whether the rest had held rest_time at each sample; acc_out (N×3, m/s², None: not\n"
          "wanted): acc freed of the online lever arm's accelerations.");

    // ---- heading, with the hard-iron fit and the magnetometer's delay
    nb::list heading_names;
    add_names(heading_names, HEADING_STATE_FIELDS, HEADING_N_FIELDS);
    add_names(heading_names, HARD_IRON_STATE_FIELDS, HARD_IRON_N_FIELDS, "hard_iron_");
    add_names(heading_names, MAG_DELAY_STATE_FIELDS, MAG_DELAY_N_FIELDS, "mag_delay_");
    m.attr("HEADING_STATE_NAMES") = state_names(heading_names, doubles<AfHeading>());
    m.attr("GUARD_NOISE_MARGIN") = GUARD_NOISE_MARGIN;
    m.attr("MAG_SPAN_S") = MAG_SPAN_S;
    m.attr("MAG_DELAY_REACH_S") = MAG_DELAY_REACH_S;
    m.attr("MAG_DELAY_SIGMAS") = MAG_DELAY_SIGMAS;
    m.attr("MAG_DELAY_MIN_S") = MAG_DELAY_MIN_S;
    m.attr("MAG_DELAY_CLEAN_S") = MAG_DELAY_CLEAN_S;
    m.def("heading_coefficients", [](nb::handle params, double Ts) {
        double resolved[AF_N_PARAMS];
        resolved_params(AF_STAGE_heading, params, resolved);
        check_step(Ts);
        auto coef = new_vector(doubles<AfHeadingCoef>());
        check_coefficients(heading_coefficients(resolved, Ts, as<AfHeadingCoef>(coef, "coef")), AF_STAGE_heading, Ts);
        return coef;
    }, nb::arg("params").none(), nb::arg("Ts"),
          "The heading stage's coefficients at the step (IMU sample) time Ts (s) from its parameters (None: unset).");
    m.def("heading_initial_state", []() {
        auto state = new_vector(doubles<AfHeading>());
        heading_initial_state(as<AfHeading>(state, "state"));
        return state;
    }, "The heading stage's state before any sample.");
    m.def("heading_run", [](Vector state, const Vector &coef, const Rows4 &quat, const Rows3 &mag, Rows4 out,
                            Flags accepted, Rows3 offset, Vector delay) {
        AfHeading *s = as<AfHeading>(state, "state");
        const AfHeadingCoef *c = as<AfHeadingCoef>(coef, "coef");
        size_t n = heading_rows(quat, mag, out, accepted, offset, delay);
        nb::gil_scoped_release unlocked;
        heading_run(s, c, n, quat.data(), mag.data(), out.data(), reinterpret_cast<unsigned char *>(accepted.data()),
                    offset.data(), delay.data());
    }, nb::arg("state").noconvert(), nb::arg("coef"), nb::arg("quat"), nb::arg("mag"), nb::arg("out").noconvert(),
          nb::arg("accepted").noconvert(), nb::arg("offset").noconvert(), nb::arg("delay").noconvert(),
          "Over N samples quat (N×4, sensor → earth) and mag (N×3; a row with a NaN: no field sample): the\n"
          "orientation with magnetometer heading into out (N×4; may be quat), whether the field was used into\n"
          "accepted (N), the hard-iron estimate into offset (N×3) and the delay allowed for (s) into delay\n"
          "(N); state in place.");

    m.def("heading_smooth", [](const Vector &coef, const Rows4 &quat, const Rows3 &mag, Rows4 out, Flags accepted,
                               Rows3 offset, Vector delay) {
        const AfHeadingCoef *c = as<AfHeadingCoef>(coef, "coef");
        size_t n = heading_rows(quat, mag, out, accepted, offset, delay);
        if (n > 0 && out.data() == quat.data()) throw nb::value_error("out must not be quat");
        if (std::isnan(c->delay)) throw nb::value_error("the smoothed heading needs mag_delay given");
        nb::gil_scoped_release unlocked;
        offline_heading(c, n, quat.data(), mag.data(), out.data(), reinterpret_cast<unsigned char *>(accepted.data()),
                        offset.data(), delay.data());
    }, nb::arg("coef"), nb::arg("quat"), nb::arg("mag"), nb::arg("out").noconvert(), nb::arg("accepted").noconvert(),
          nb::arg("offset").noconvert(), nb::arg("delay").noconvert(),
          "The heading stage smoothed forward and backward in time (blocks/core/pipeline/offline.h) over N samples\n"
          "quat (N×4) and mag (N×3), coef's mag_delay given: out (N×4, not quat), accepted (N: used by either\n"
          "pass), the forward pass's hard-iron estimate offset (N×3) and delay (N, s) written.");

    // ---- sample timing and latency
    m.attr("STEP_TOLERANCE") = STEP_TOLERANCE;
    m.attr("GRID_TOLERANCE") = GRID_TOLERANCE;
    m.attr("GRID_MAX_SAMPLES") = GRID_MAX_SAMPLES;
    m.attr("MAX_LATENCY_S") = MAX_LATENCY_S;
    m.def("check_latency", [](double latency) {
        char message[MESSAGE_SIZE];
        if (check_latency(latency, message, sizeof message)) throw nb::value_error(message);
        return latency;
    }, nb::arg("latency"), "latency (s), refused unless finite and within ±MAX_LATENCY_S.");
    m.attr("GYR_SAMPLES") = nb::make_tuple(GYR_SAMPLES[0], GYR_SAMPLES[1]);
    m.attr("ACC_SAMPLES") = nb::make_tuple(ACC_SAMPLES[0], ACC_SAMPLES[1]);
    m.def("check_samples", [](nb::handle gyr_samples, nb::handle acc_samples) {
        char message[MESSAGE_SIZE], text[64];
        const char *stand_in = ""; /* for a value that is not a string: refused, then named by its repr */
        bool gyr_text = nb::isinstance<nb::str>(gyr_samples), acc_text = nb::isinstance<nb::str>(acc_samples);
        std::string gyr = gyr_text ? nb::cast<std::string>(gyr_samples) : stand_in;
        std::string acc = acc_text ? nb::cast<std::string>(acc_samples) : stand_in;
        if (check_samples(gyr.c_str(), acc.c_str(), message, sizeof message) == 0) return;
        bool gyr_refused = std::string(message).rfind("gyr_samples", 0) == 0;
        std::string refusal = message;
        if (gyr_refused ? !gyr_text : !acc_text)
            refusal = replaced(refusal, std::string("got ") + str_repr(stand_in, text, sizeof text),
                               std::string("got ") + nb::repr(gyr_refused ? gyr_samples : acc_samples).c_str());
        throw nb::value_error(refusal.c_str());
    }, nb::arg("gyr_samples").none(), nb::arg("acc_samples").none(),
          "Refused (ValueError) unless gyr_samples is one of GYR_SAMPLES and acc_samples one of ACC_SAMPLES.");
    m.def("same_step", [](double Ts, double reference) { return same_step(Ts, reference) != 0; },
          nb::arg("Ts"), nb::arg("reference"),
          "Whether the sample time Ts (s) is reference (s) up to STEP_TOLERANCE.");
    m.def("grid_samples", &grid_samples, nb::arg("start"), nb::arg("Ts"), nb::arg("t"), nb::arg("h"),
          "The instants start + k*Ts (s, k >= 1) that a communication step from t over h (s) reaches, up to "
          "GRID_TOLERANCE samples: the samples an FMU with the sample time Ts runs in it, its inputs held.");
    m.def("grid_before", &grid_before, nb::arg("start"), nb::arg("Ts"), nb::arg("t"),
          "The grid's instant start + k*Ts (s) at t or, up to GRID_TOLERANCE, last before it: where the samples "
          "a step from t runs begin.");
    m.def("carry_forward_rows", [](Rows4 quat, Rows3 gravity, const Rows3 &gyr, double latency) {
        size_t n = quat.shape(0);
        check_rows(gravity.shape(0), n, "gravity");
        check_rows(gyr.shape(0), n, "gyr");
        nb::gil_scoped_release unlocked;
        carry_forward_rows(n, quat.data(), gravity.data(), gyr.data(), latency);
    }, nb::arg("quat").noconvert(), nb::arg("gravity").noconvert(), nb::arg("gyr"), nb::arg("latency"),
          "Every row of quat (N×4) and gravity (N×3) carried forward over latency (s) at the rates gyr\n"
          "(N×3, rad/s), in place.");
    m.def("interval_ends", [](const Rows3 &gyr, const Rows3 &acc, double Ts, Rows3 out) {
        size_t n = acc.shape(0);
        check_rows(gyr.shape(0), n, "gyr");
        check_rows(out.shape(0), n, "out");
        nb::gil_scoped_release unlocked;
        interval_ends(n, gyr.data(), acc.data(), Ts, out.data());
    }, nb::arg("gyr"), nb::arg("acc"), nb::arg("Ts"), nb::arg("out").noconvert(),
          "Accelerometer means acc (N×3, m/s²) over each sample time Ts (s) in the sensor frame at its end,\n"
          "at the mean rates gyr (N×3, rad/s), into out (N×3).");

    // ---- the delay measurement
    m.def("carry_spans", [](const Rows4 &quat, const Rows3 &gyr, double Ts, const Vector &x0, const Vector &x1,
                            nb::ndarray<double, nb::shape<-1, 3, 3>, nb::c_contig, nb::device::cpu> matrices) {
        size_t n = quat.shape(0), spans = x0.shape(0);
        check_rows(gyr.shape(0), n, "gyr");
        check_rows(x1.shape(0), spans, "x1");
        check_rows(matrices.shape(0), spans, "matrices");
        if (n < 2) throw nb::value_error("carry_spans needs two samples or more");
        nb::gil_scoped_release unlocked;
        carry_spans(n, quat.data(), gyr.data(), Ts, spans, x0.data(), x1.data(), matrices.data());
    }, nb::arg("quat"), nb::arg("gyr"), nb::arg("Ts"), nb::arg("x0"), nb::arg("x1"), nb::arg("matrices").noconvert(),
          "Per span j: matrices[j] = R_Δᵀ, R_Δ the sensor's turn from the fractional sample index x0[j] to\n"
          "x1[j] (held within the recording); quat (N×4): the sensor at t_k integrated from gyr (N×3, rad/s,\n"
          "over Ts s each).");
    // the checks of a prediction's arguments (blocks/core/stages/prediction.h), before the lock is released
    auto check_prediction = [](const Rows3 &gyr, const Rows3 &acc, const Rows3 &gravity, double Ts, size_t horizon) {
        size_t n = gyr.shape(0);
        check_rows(acc.shape(0), n, "acc");
        check_rows(gravity.shape(0), n, "gravity");
        if (!(std::isfinite(Ts) && Ts > 0.0)) throw nb::value_error("Ts must be a finite positive number of seconds");
        if (horizon < 1 || horizon >= n)
            throw nb::value_error(("the horizon must be 1 to " + std::to_string(n) + " - 1 samples, got " +
                                   std::to_string(horizon)).c_str());
        return n;
    };
    m.def("lever_arm_sums", [](const Rows3 &gyr, const Rows3 &acc, double Ts, size_t span, size_t window) {
        size_t n = gyr.shape(0);
        check_rows(acc.shape(0), n, "acc");
        if (n < 1) throw nb::value_error("the lever-arm fit needs a sample or more");
        if (!(std::isfinite(Ts) && Ts > 0.0)) throw nb::value_error("Ts must be a finite positive number of seconds");
        if (span < 1) throw nb::value_error("span must be 1 sample or more");
        if (window < 1) throw nb::value_error("window must be 1 sample or more");
        auto normal = new_vector(9), moment = new_vector(3);
        double total;
        {
            nb::gil_scoped_release unlocked;
            lever_arm_sums(n, gyr.data(), acc.data(), Ts, span, window, normal.data(), moment.data(), &total);
        }
        return nb::make_tuple(normal, moment, total);
    }, nb::arg("gyr"), nb::arg("acc"), nb::arg("Ts"), nb::arg("span"), nb::arg("window"),
          "(normal (9, X^T.X row-major), moment (3, X^T.y), total (sum |y|^2)) of the lever-arm fit y = X.r over\n"
          "gyr (N×3, rad/s, over Ts s each) and acc (N×3, m/s²), ω and α from the gyro's means over `span` samples\n"
          "either side of each, y and X freed of their means in consecutive windows of `window` samples\n"
          "(blocks/core/stages/lever_arm.h).");
    m.def("lever_arm_removed", [](const Rows3 &gyr, const Rows3 &acc, double Ts, size_t span, const Three &r,
                                  Rows3 out) {
        size_t n = gyr.shape(0);
        check_rows(acc.shape(0), n, "acc");
        check_rows(out.shape(0), n, "out");
        if (!(std::isfinite(Ts) && Ts > 0.0)) throw nb::value_error("Ts must be a finite positive number of seconds");
        if (span < 1) throw nb::value_error("span must be 1 sample or more");
        nb::gil_scoped_release unlocked;
        lever_arm_removed(n, gyr.data(), acc.data(), Ts, span, r.data(), out.data());
    }, nb::arg("gyr"), nb::arg("acc"), nb::arg("Ts"), nb::arg("span"), nb::arg("r"), nb::arg("out").noconvert(),
          "out (N×3, m/s²) = acc less α×r + ω×(ω×r) for r (3, m) as lever_arm_sums takes them\n"
          "(blocks/core/stages/lever_arm.h).");
    m.def("prediction_error", [check_prediction](const Rows3 &gyr, const Rows3 &acc, const Rows3 &gravity, double Ts,
                                                 size_t horizon) {
        size_t n = check_prediction(gyr, acc, gravity, Ts, horizon);
        std::vector<double> work(3 * horizon);
        nb::gil_scoped_release unlocked;
        return prediction_error(n, gyr.data(), acc.data(), gravity.data(), Ts, horizon, work.data());
    }, nb::arg("gyr"), nb::arg("acc"), nb::arg("gravity"), nb::arg("Ts"), nb::arg("horizon"),
          "The mean over k ≥ horizon of |acc[k] − R_kᵀ·R_(k−horizon)·gravity[k−horizon]|² (m²/s⁴), R_k the\n"
          "sensor's orientation integrated from gyr (N×3, rad/s, over Ts s each); acc and gravity N×3, m/s²\n"
          "(blocks/core/stages/prediction.h).");
    m.def("prediction_errors", [check_prediction](const Rows3 &gyr, const Rows3 &acc, const Rows3 &gravity,
                                                  double Ts, size_t horizon, size_t block) {
        size_t n = check_prediction(gyr, acc, gravity, Ts, horizon);
        if (block < 1) throw nb::value_error("block must be 1 sample or more");
        std::vector<double> work(3 * horizon);
        auto means = new_vector((n - horizon + block - 1) / block);
        {
            nb::gil_scoped_release unlocked;
            prediction_errors(n, gyr.data(), acc.data(), gravity.data(), Ts, horizon, block, work.data(), means.data());
        }
        return means;
    }, nb::arg("gyr"), nb::arg("acc"), nb::arg("gravity"), nb::arg("Ts"), nb::arg("horizon"), nb::arg("block"),
          "prediction_error's squared differences, their means over consecutive blocks of `block` of the k ≥\n"
          "horizon (the last holds those left over) (m²/s⁴; blocks/core/stages/prediction.h).");
}

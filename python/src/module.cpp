// softrne._softrne: the Python bindings (nanobind). Every function here converts arguments and
// results and calls the library; none computes dynamics, reads files or builds reports itself:
// the algorithms are softrne's (rnea.hpp, mass_matrix.hpp, ...), the files are read and written
// by softrne::io, the simulation is softrne::sim::simulate_arm (as softrne-sim runs it) and
// the reports are tools/common/report.hpp's (as softrne-fit and softrne-loop write them).
//
// Arrays: numpy arrays of float64 in C order pass without a copy; anything else numpy can turn
// into one (lists, float32, strided views) is converted first. A state is a vector (nq,), a
// batch of states an array (N, nq); results have the same leading shape. Batches run without
// the GIL on several threads, one workspace (DynamicChainData) per thread.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <csignal>
#include <optional>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nanobind/nanobind.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

// numpy's C API: arguments read and results made in a few ns (nanobind's ndarray import and
// export cost about 0.2 and 0.6 us each, more than the dynamics of a small arm).
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include "common/recordings.hpp"
#include "common/report.hpp"
#include "softrne/algorithms/derivatives.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/equilibrium.hpp"
#include "softrne/fit/arm_fit.hpp"
#include "softrne/fit/loop.hpp"
#include "softrne/fit/parallel_for.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/sim/arm_jacobian.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "softrne/sim/closed_loop.hpp"
#include "softrne/sim/linearisation.hpp"
#include "softrne/softrne.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using Chain = softrne::DynamicChain<double>;
using Data = softrne::DynamicChainData<double>;
using CVec = Eigen::Map<const Eigen::VectorXd>;
using Vec = Eigen::Map<Eigen::VectorXd>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// \brief A robot: its description (the robot file), the arm built from it (build_arm) and
/// the chain of the arm's bodies (ArmDescription::make_chain, which the simulation uses too),
/// with one workspace for single calls (they hold the GIL, so it is never shared).
struct Robot {
  softrne::ArmDescription desc;
  Chain chain;
  Data data;

  Robot(const softrne::io::RobotSpec& spec, const std::string& source)
      : desc(build(spec, source)), chain(desc.make_chain<double>()), data(chain.make_data()) {}

  int nq() const { return chain.num_coordinates(); }

  /// build_arm's std::invalid_argument (an effect that does not fit the arm) as the tools
  /// report it (softrne-sim): an InputError naming the file and the field "effects".
  static softrne::ArmDescription build(const softrne::io::RobotSpec& spec, const std::string& source) {
    try {
      return softrne::build_arm(spec);
    } catch (const std::invalid_argument& e) {
      throw softrne::io::InputError(softrne::io::Category::InvalidValue, source, "effects", e.what());
    }
  }
};

bool any_object(PyObject*) { return true; }
bool is_ndarray(PyObject* o) { return PyArray_Check(o); }

/// \brief An array argument: anything numpy can read as an array of numbers (the name is
/// what the signatures and the stubs show).
class ArrayLike : public nb::object {
  NB_OBJECT_DEFAULT(ArrayLike, nb::object, "numpy.typing.ArrayLike", any_object)
};
/// \brief A result: a new numpy array of float64.
class NDArray : public nb::object {
  NB_OBJECT_DEFAULT(NDArray, nb::object, "numpy.typing.NDArray[numpy.float64]", is_ndarray)
};
using OutArray = NDArray;
/// \brief A controller argument (simulate_closed_loop checks that it is callable).
class ControllerFunction : public nb::object {
  NB_OBJECT_DEFAULT(ControllerFunction, nb::object,
                    "collections.abc.Callable[[ControllerInput], numpy.typing.ArrayLike]", any_object)
};

/// \brief An argument as a C-contiguous float64 numpy array: the argument itself where it is
/// one (read through the numpy C API, no copy: a few ns), else a converted copy.
class Array {
 public:
  Array() = default;
  Array(PyArrayObject* a, nb::object keep) : a_(a), keep_(std::move(keep)) {}
  size_t ndim() const { return static_cast<size_t>(PyArray_NDIM(a_)); }
  size_t shape(size_t i) const { return static_cast<size_t>(PyArray_DIM(a_, static_cast<int>(i))); }
  const double* data() const { return static_cast<const double*>(PyArray_DATA(a_)); }

 private:
  PyArrayObject* a_ = nullptr;  ///< borrowed from the caller's argument, or owned by keep_
  nb::object keep_;
};

std::string shape_text(const Array& a) {
  std::string s = "(";
  for (size_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// \brief `h` as a C-contiguous float64 array (the argument itself where it already is one:
/// it stays referenced by the caller for the duration of the call).
Array as_array(nb::handle h, const char* fn, const char* name) {
  if (h.is_none()) throw nb::type_error((std::string("softrne.") + fn + ": " + name + " is None").c_str());
  PyObject* o = h.ptr();
  if (PyArray_Check(o)) {
    auto* a = reinterpret_cast<PyArrayObject*>(o);
    if (PyArray_TYPE(a) == NPY_DOUBLE && PyArray_IS_C_CONTIGUOUS(a) && PyArray_ISALIGNED(a) &&
        PyArray_ISNOTSWAPPED(a))
      return Array(a, nb::object());
  }
  PyObject* c = PyArray_FROMANY(o, NPY_DOUBLE, 0, 0, NPY_ARRAY_IN_ARRAY);
  if (!c) {
    nb::python_error e;
    throw nb::value_error((std::string("softrne.") + fn + ": " + name + " is not an array of numbers (" +
                           e.what() + ")")
                              .c_str());
  }
  return Array(reinterpret_cast<PyArrayObject*>(c), nb::steal(c));
}

/// \brief The arguments of one algorithm: each (nq,) (one state) or (N, nq) (a batch), all alike.
struct States {
  std::array<Array, 3> arrays;  ///< fixed storage: no allocation per call
  size_t count = 0;             ///< arguments
  size_t n = 1;                 ///< states
  bool batched = false;         ///< 2-D arguments
  const double* row(size_t arg, size_t k, int nq) const {
    return arrays[arg].data() + k * static_cast<size_t>(nq);
  }
};

States states(const Robot& r, const char* fn, std::initializer_list<std::pair<const char*, nb::handle>> args) {
  States s;
  const int nq = r.nq();
  const char* first = nullptr;
  for (const auto& [name, h] : args) {
    Array a = as_array(h, fn, name);
    const bool ok = (a.ndim() == 1 || a.ndim() == 2) && a.shape(a.ndim() - 1) == static_cast<size_t>(nq);
    if (!ok)
      throw nb::value_error((std::string("softrne.") + fn + ": " + name + " has shape " + shape_text(a) +
                             "; the robot has " + std::to_string(nq) + " coordinates: expected (" +
                             std::to_string(nq) + ",) or (N, " + std::to_string(nq) + ")")
                                .c_str());
    const bool batched = a.ndim() == 2;
    const size_t n = batched ? a.shape(0) : 1;
    if (!first) {
      first = name;
      s.batched = batched;
      s.n = n;
    } else if (batched != s.batched || n != s.n) {
      throw nb::value_error((std::string("softrne.") + fn + ": " + name + " has shape " + shape_text(a) +
                             " but " + first + " has shape " + shape_text(s.arrays[0]) +
                             ": give every argument as one state (nq,) or all as N states (N, nq)")
                                .c_str());
    }
    s.arrays[s.count++] = std::move(a);
  }
  return s;
}

/// \brief A new numpy array of float64 of shape shape[0..nd) (numpy C API); `out` its data.
OutArray new_array(size_t nd, const size_t* shape, double*& out) {
  npy_intp dims[4];
  for (size_t i = 0; i < nd; ++i) dims[i] = static_cast<npy_intp>(shape[i]);
  PyObject* a = PyArray_SimpleNew(static_cast<int>(nd), dims, NPY_DOUBLE);
  if (!a) throw nb::python_error();
  out = static_cast<double*>(PyArray_DATA(reinterpret_cast<PyArrayObject*>(a)));
  return nb::steal<NDArray>(a);
}
OutArray new_array(std::initializer_list<size_t> shape, double*& out) {
  return new_array(shape.size(), shape.begin(), out);
}

int thread_count(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw ? static_cast<int>(hw) : 1;
}

/// \brief Evaluates `kernel(data, inputs, out)` for every state: in the robot's own workspace
/// for one state (GIL held), else without the GIL on up to `threads` threads (0: one per
/// core), one workspace per thread. `out_size` doubles per state; `out_shape` the shape of
/// one state's result.
template <class Kernel>
OutArray evaluate(Robot& r, const States& s, std::initializer_list<size_t> out_shape, int threads, Kernel kernel) {
  size_t per_state = 1;
  for (size_t d : out_shape) per_state *= d;
  const int nq = r.nq();
  const size_t nargs = s.count;
  double* out = nullptr;
  std::array<size_t, 4> shape{};
  size_t nd = 0;
  if (s.batched) shape[nd++] = s.n;
  for (size_t d : out_shape) shape[nd++] = d;
  OutArray result = new_array(nd, shape.data(), out);
  const double* in[3] = {nullptr, nullptr, nullptr};
  if (!s.batched) {
    for (size_t a = 0; a < nargs; ++a) in[a] = s.arrays[a].data();
    kernel(r.data, in, out);
    return result;
  }
  if (s.n == 0) return result;
  // Chunks of states handed out to the threads; enough of them to balance the load.
  const int workers = std::max(1, std::min<int>(thread_count(threads), static_cast<int>((s.n + 63) / 64)));
  const size_t chunk = std::max<size_t>(64, (s.n + 8 * workers - 1) / (8 * workers));
  const int chunks = static_cast<int>((s.n + chunk - 1) / chunk);
  {
    nb::gil_scoped_release release;
    std::vector<Data> datas(static_cast<size_t>(workers), r.chain.make_data());
    softrne::fit::parallel_for_workers(chunks, workers, [&](int c, int w) {
      Data& d = datas[static_cast<size_t>(w)];
      const double* rows[3] = {nullptr, nullptr, nullptr};
      const size_t end = std::min(s.n, (static_cast<size_t>(c) + 1) * chunk);
      for (size_t k = static_cast<size_t>(c) * chunk; k < end; ++k) {
        for (size_t a = 0; a < nargs; ++a) rows[a] = s.row(a, k, nq);
        kernel(d, rows, out + k * per_state);
      }
    });
  }
  return result;
}

const char* const kThreadsDoc =
    "\n\nThe arguments are one state each (shape (nq,)) or N states each (shape (N, nq)); N "
    "states run without the GIL on `threads` threads (0: one per core), one workspace per "
    "thread, and the result gains a leading axis N.";

// ---- robot files and dicts ----------------------------------------------------------------

nb::object json_module() { return nb::module_::import_("json"); }

/// A JSON text (nlohmann) as Python objects, by Python's json module.
nb::object to_python(const nlohmann::ordered_json& j) { return json_module().attr("loads")(j.dump()); }

Robot robot_from_dict(nb::handle d, const std::string& source) {
  // numpy arrays and scalars inside the dict become lists and floats.
  nb::object default_fn = nb::cpp_function([](nb::handle o) -> nb::object {
    if (nb::hasattr(o, "tolist")) return o.attr("tolist")();
    throw nb::type_error(("not JSON serialisable: " + std::string(nb::str(nb::handle(o.type())).c_str())).c_str());
  });
  std::string text;
  try {
    text = nb::cast<std::string>(json_module().attr("dumps")(d, "default"_a = default_fn));
  } catch (nb::python_error& e) {
    throw softrne::io::InputError(softrne::io::Category::WrongType, source, "",
                                  std::string("cannot be written as JSON: ") + e.what());
  }
  return Robot(softrne::io::parse_robot_json(text, source), source);
}

// ---- data sets -------------------------------------------------------------------------

/// A matrix as a numpy array (a copy, C order).
OutArray matrix_out(const Eigen::MatrixXd& m) {
  double* out = nullptr;
  OutArray a = new_array({static_cast<size_t>(m.rows()), static_cast<size_t>(m.cols())}, out);
  Eigen::Map<RowMatrix>(out, m.rows(), m.cols()) = m;
  return a;
}
OutArray vector_out(const Eigen::VectorXd& v) {
  double* out = nullptr;
  OutArray a = new_array({static_cast<size_t>(v.size())}, out);
  Vec(out, v.size()) = v;
  return a;
}

/// A (rows, cols) argument as a matrix; ValueError naming it and both shapes otherwise.
Eigen::MatrixXd matrix_in(nb::handle h, const char* fn, const char* name, Eigen::Index rows, Eigen::Index cols) {
  Array a = as_array(h, fn, name);
  const bool ok = (a.ndim() == 2 && static_cast<Eigen::Index>(a.shape(0)) == rows &&
                   static_cast<Eigen::Index>(a.shape(1)) == cols) ||
                  (a.ndim() == 1 && cols == 1 && static_cast<Eigen::Index>(a.shape(0)) == rows) ||
                  (a.ndim() == 1 && rows == 1 && static_cast<Eigen::Index>(a.shape(0)) == cols);
  if (!ok)
    throw nb::value_error((std::string("softrne.") + fn + ": " + name + " has shape " + shape_text(a) +
                           "; expected (" + std::to_string(rows) + ", " + std::to_string(cols) + ")")
                              .c_str());
  return Eigen::Map<const RowMatrix>(a.data(), rows, cols);
}

Eigen::VectorXd vector_in(nb::handle h, const char* fn, const char* name, Eigen::Index size = -1) {
  Array a = as_array(h, fn, name);
  if (a.ndim() != 1 || (size >= 0 && static_cast<Eigen::Index>(a.shape(0)) != size))
    throw nb::value_error((std::string("softrne.") + fn + ": " + name + " has shape " + shape_text(a) +
                           "; expected (" + (size >= 0 ? std::to_string(size) : std::string("N")) + ",)")
                              .c_str());
  return CVec(a.data(), static_cast<Eigen::Index>(a.shape(0)));
}

/// A data set from arrays (the same fields read_dataset fills), for fit() and loop().
softrne::io::Dataset dataset_from_arrays(const Robot& r, const ArrayLike& t, const ArrayLike& pressures, const ArrayLike& angles,
                                         const std::string& source) {
  softrne::io::Dataset d;
  d.t = vector_in(t, "Dataset", "t");
  const Eigen::Index N = d.t.size();
  if (N < 2) throw nb::value_error("softrne.Dataset: t has fewer than 2 samples");
  for (Eigen::Index i = 1; i < N; ++i)
    if (!(d.t(i) > d.t(i - 1)))
      throw nb::value_error(("softrne.Dataset: t is not strictly increasing at index " + std::to_string(i)).c_str());
  d.pressures = matrix_in(pressures, "Dataset", "pressures", N, r.desc.num_inputs);
  d.has_angles = !angles.is_none();
  d.angles = d.has_angles ? matrix_in(angles, "Dataset", "angles", N, r.desc.nq) : Eigen::MatrixXd(N, 0);
  d.pressure_names = r.desc.pressure_names;
  d.angle_names = r.desc.coordinate_names;
  d.source = source;
  return d;
}

// ---- simulation ------------------------------------------------------------------------

using PI = softrne::sim::ArmSimulationOptions::PressureInterpolation;
using JM = softrne::sim::ArmSimulationOptions::JacobianMethod;

double positive_number(nb::handle v, const std::string& key, const char* fn = "simulate") {
  double x = 0;
  if (!nb::try_cast(v, x) || !(x > 0) || !std::isfinite(x))
    throw nb::value_error(("softrne." + std::string(fn) + ": " + key + " must be a positive number").c_str());
  return x;
}

/// The solver options of softrne-sim, by the names of its command-line options
/// (atol_velocity for --atol-velocity), for the function `fn`. `held`: the pressures are held
/// between samples (simulate_closed_loop), so interpolation and smooth do not apply.
softrne::sim::ArmSimulationOptions simulation_options(const nb::kwargs& kw, double t0, double t1,
                                                      const char* fn = "simulate", bool held = false) {
  const std::string prefix = "softrne." + std::string(fn) + ": ";
  softrne::sim::ArmSimulationOptions opt;
  long max_steps = 0;
  double atol_velocity = 0;
  for (auto [k, v] : kw) {
    const std::string key = nb::cast<std::string>(k);
    if (key == "rtol") {
      opt.cvode.rtol = positive_number(v, key, fn);
    } else if (key == "atol") {
      opt.cvode.atol = positive_number(v, key, fn);
    } else if (key == "atol_velocity") {
      atol_velocity = positive_number(v, key, fn);
    } else if (key == "smooth") {
      opt.pressure_smoothing = positive_number(v, key, fn);
    } else if (key == "max_wall_seconds") {
      opt.cvode.max_wall_seconds = positive_number(v, key, fn);
    } else if (key == "max_steps") {
      if (!nb::try_cast(v, max_steps) || max_steps < 1)
        throw nb::value_error((prefix + "max_steps must be a positive integer").c_str());
    } else if (held && (key == "interpolation" || key == "smooth")) {
      throw nb::type_error((prefix + "solver option '" + key +
                            "' does not apply: the pressures are held between samples")
                               .c_str());
    } else if (key == "interpolation") {
      std::string m;
      if (!nb::try_cast(v, m) || (m != "pchip" && m != "linear" && m != "zoh"))
        throw nb::value_error((prefix + "interpolation must be 'pchip', 'linear' or 'zoh'").c_str());
      opt.interpolation = m == "pchip" ? PI::pchip : m == "linear" ? PI::linear : PI::zero_order_hold;
    } else if (key == "jacobian") {
      std::string m;
      if (!nb::try_cast(v, m) || (m != "ad" && m != "ad-forward" && m != "fd"))
        throw nb::value_error((prefix + "jacobian must be 'ad', 'ad-forward' or 'fd'").c_str());
      opt.autodiff_jacobian = m != "fd";
      opt.jacobian_method = m == "ad-forward" ? JM::forward_dynamics : JM::inverse_dynamics;
    } else {
      throw nb::type_error((prefix + "unknown solver option '" + key + "' (known: rtol, atol, atol_velocity, " +
                            (held ? "" : "interpolation, smooth, ") + "jacobian, max_steps, max_wall_seconds)")
                               .c_str());
    }
  }
  if (atol_velocity > 0) opt.velocity_atol_factor = atol_velocity / opt.cvode.atol;
  // softrne-sim's default step limit.
  opt.cvode.max_steps = max_steps > 0 ? max_steps : std::max(100000L, static_cast<long>(1e4 * (t1 - t0)));
  return opt;
}

/// Set by Ctrl-C while a simulation, fit or loop runs (InterruptScope); CVODE's stop pointer
/// watches it, so the run ends within one simulation step, as the tools' do.
std::atomic<bool> g_interrupted{false};
extern "C" void on_sigint(int) { g_interrupted.store(true); }

/// \brief Ctrl-C during a long C++ run without the GIL: Python's own SIGINT handler only
/// sets a flag that no Python code looks at until the run ends, so for its duration (called
/// from the main thread, where Python receives signals) a C handler sets g_interrupted, and
/// Python's handler is restored afterwards. raise_if_interrupted() then raises
/// KeyboardInterrupt.
class InterruptScope {
 public:
  InterruptScope() {
    g_interrupted.store(false);
    const bool main_thread =
        nb::module_::import_("threading").attr("main_thread")().is(nb::module_::import_("threading").attr("current_thread")());
    if (main_thread) {
      previous_ = std::signal(SIGINT, on_sigint);
      installed_ = previous_ != SIG_ERR;
    }
  }
  ~InterruptScope() {
    if (installed_) std::signal(SIGINT, previous_);
  }
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
  const std::atomic<bool>* flag() const { return &g_interrupted; }

 private:
  bool installed_ = false;
  void (*previous_)(int) = nullptr;
};

/// With the GIL, after the InterruptScope ended: the KeyboardInterrupt of a Ctrl-C.
void raise_if_interrupted() {
  if (!g_interrupted.load()) return;
  g_interrupted.store(false);
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw nb::python_error();
}

/// Runs `f` without the GIL and with Ctrl-C watched; a failure caused by the interrupt
/// (a simulation stopped on request) is a KeyboardInterrupt.
template <class F>
auto run_interruptible(F&& f) {
  std::optional<decltype(f(g_interrupted))> result;
  try {
    InterruptScope scope;
    nb::gil_scoped_release release;
    result.emplace(f(g_interrupted));
  } catch (const std::exception&) {
    raise_if_interrupted();
    throw;
  }
  raise_if_interrupted();
  return std::move(*result);
}

// ---- linearisation and control in the loop -----------------------------------------------

namespace sim = softrne::sim;

/// A vector argument of the robot's size `size` (its `what`: "states", "pressures", ...):
/// ValueError naming the function, the argument and both sizes otherwise.
Eigen::VectorXd robot_vector(nb::handle h, const char* fn, const char* name, Eigen::Index size, const char* what) {
  Array a = as_array(h, fn, name);
  if (a.ndim() != 1 || static_cast<Eigen::Index>(a.shape(0)) != size)
    throw nb::value_error((std::string("softrne.") + fn + ": " + name + " has shape " + shape_text(a) +
                           "; the robot has " + std::to_string(size) + " " + what + ": expected (" +
                           std::to_string(size) + ",)")
                              .c_str());
  return CVec(a.data(), size);
}

std::string number_text(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

void check_sample_time(double h, const char* fn) {
  if (!(h > 0) || !std::isfinite(h))
    throw nb::value_error((std::string("softrne.") + fn + ": h must be positive and finite (got " + number_text(h) + ")")
                              .c_str());
}

/// \brief What a Python controller receives at a sample (sim::ControllerInput as numpy
/// arrays, new ones at every sample: the controller may keep them).
struct ControllerObservation {
  int k = 0;
  double t = 0;
  OutArray angles, velocities, state;
};

/// Raises (as a C++ nb::python_error) a Python exception of `type` with `message`.
[[noreturn]] void raise_python(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw nb::python_error();
}

/// The pressures a Python controller returned at sample `in`: num_pressures finite numbers,
/// else TypeError (None) or ValueError naming the sample and what was wrong. GIL held.
Eigen::VectorXd controller_pressures(const Robot& r, nb::handle ret, const sim::ControllerInput& in) {
  const int m = r.desc.num_inputs;
  const std::string at = "softrne.simulate_closed_loop: the controller at t = " + number_text(in.t) + " s (sample " +
                         std::to_string(in.k) + ") returned ";
  const std::string expected = "; the robot has " + std::to_string(m) + " pressures: expected (" + std::to_string(m) + ",)";
  if (ret.is_none()) raise_python(PyExc_TypeError, at + "None" + expected);
  PyObject* c = PyArray_FROMANY(ret.ptr(), NPY_DOUBLE, 0, 0, NPY_ARRAY_IN_ARRAY);
  if (!c) {
    nb::python_error e;
    raise_python(PyExc_ValueError, at + "something that is not an array of numbers (" +
                                       std::string(nb::str(e.value()).c_str()) + ")" + expected);
  }
  nb::object keep = nb::steal(c);
  auto* a = reinterpret_cast<PyArrayObject*>(c);
  std::string shape = "(";
  for (int i = 0; i < PyArray_NDIM(a); ++i) shape += (i ? ", " : "") + std::to_string(PyArray_DIM(a, i));
  shape += PyArray_NDIM(a) == 1 ? ",)" : ")";
  if (PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != m) raise_python(PyExc_ValueError, at + "shape " + shape + expected);
  const Eigen::VectorXd p = CVec(static_cast<const double*>(PyArray_DATA(a)), m);
  for (int i = 0; i < m; ++i)
    if (!std::isfinite(p(i)))
      raise_python(PyExc_ValueError, at + "a non-finite pressure (" + r.desc.pressure_names[static_cast<size_t>(i)] +
                                         " = " + number_text(p(i)) + ")");
  return p;
}

nb::dict stats_dict(const sim::SimulationStats& s) {
  nb::dict d;
  d["steps"] = s.steps;
  d["rhs_evals"] = s.rhs_evals;
  d["jac_evals"] = s.jac_evals;
  d["rhs_evals_for_jacobian_fd"] = s.rhs_evals_for_jacobian_fd;
  d["error_test_failures"] = s.error_test_failures;
  d["nonlinear_convergence_failures"] = s.nonlinear_convergence_failures;
  d["restarts"] = s.restarts;
  d["wall_seconds"] = s.wall_seconds;
  return d;
}

}  // namespace

NB_MODULE(_softrne, m) {
  if (_import_array() < 0) throw nb::python_error();
  m.doc() =
      "softrne: dynamics of soft/rigid robot arms (constant-curvature pneumatic joints, rigid "
      "links, revolute joints) by the recursive Newton-Euler algorithm; simulation of recorded "
      "pressures (CVODE) and parameter fits (NLopt). The compiled core of the softrne C++ library.";

  // Exceptions: a bad input file or value -> InputError (a ValueError) with the tools' one line
  // "file: where: what" and its parts as attributes; a computation that fails on valid input ->
  // SimulationError (a RuntimeError). std::invalid_argument (wrong sizes) -> ValueError.
  static nb::object input_error = nb::steal(PyErr_NewExceptionWithDoc(
      "softrne.InputError",
      "A bad input file or value (robot file, CSV, robot dict): the one-line message of the "
      "command-line tools, 'file: where: what'. Attributes: source (the file), where (field "
      "or line), detail (what is wrong), category.",
      PyExc_ValueError, nullptr));
  static nb::object simulation_error = nb::steal(PyErr_NewExceptionWithDoc(
      "softrne.SimulationError",
      "A computation that failed on valid input: an integration that did not converge, a fit "
      "whose model does not simulate (the tools exit 1 on these).",
      PyExc_RuntimeError, nullptr));
  m.attr("InputError") = input_error;
  m.attr("SimulationError") = simulation_error;
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const softrne::io::InputError& e) {
      nb::object exc = input_error(e.what());
      exc.attr("source") = e.source();
      exc.attr("where") = e.where();
      exc.attr("detail") = e.detail();
      exc.attr("category") = softrne::io::to_string(e.category());
      PyErr_SetObject(input_error.ptr(), exc.ptr());
    } catch (const softrne::cli::Failure& e) {
      PyErr_SetString(simulation_error.ptr(), e.what());
    }
  });

  // ---- Robot ---------------------------------------------------------------------------
  nb::class_<Robot> robot(m, "Robot",
                          "A robot arm read from a softrne-robot/1 description (docs/formats.md): its "
                          "segments base to tip, gravity and effects. Immutable; the dynamics "
                          "functions take numpy arrays and return new ones.");
  robot
      .def_static(
          "from_json",
          [](const std::filesystem::path& path) {
            const std::string p = path.string();
            return Robot(softrne::io::read_robot_json(p), p);
          },
          "path"_a, "Reads and validates a robot file (softrne-robot/1). Raises InputError naming the file and field.")
      .def_static("from_dict", &robot_from_dict, "d"_a, "source"_a = "<dict>",
                  "A robot from the dict of a robot file (json.load of it, or to_dict()); numpy arrays "
                  "inside are accepted. Raises InputError naming `source` and the field.")
      .def_static(
          "from_json_text",
          [](const std::string& text, const std::string& source) {
            return Robot(softrne::io::parse_robot_json(text, source), source);
          },
          "text"_a, "source"_a = "<string>", "A robot from the text of a robot file.")
      .def(
          "to_dict",
          [](const Robot& r) {
            return nb::borrow<nb::dict>(to_python(softrne::io::to_ordered_json(softrne::to_robot_spec(r.desc))));
          },
          "The robot as the dict of its softrne-robot/1 file (keys in the documented order).")
      .def(
          "to_json",
          [](const Robot& r, const std::filesystem::path& path) {
            softrne::io::write_robot_json(softrne::to_robot_spec(r.desc), path.string());
          },
          "path"_a, "Writes the robot file (numbers round-trip exactly).")
      .def_prop_ro("name", [](const Robot& r) { return r.desc.spec.name; }, "The robot's name (may be empty).")
      .def_prop_ro("nq", &Robot::nq, "Number of coordinates (two bending angles u, v per CC joint, one per revolute joint).")
      .def_prop_ro("coordinate_names", [](const Robot& r) { return r.desc.coordinate_names; },
                   "Names of the coordinates, in order: u1, v1, u2, ... (the data sets' angle columns).")
      .def_prop_ro("pressure_names", [](const Robot& r) { return r.desc.pressure_names; },
                   "Names of the chamber pressures, in order: p1_0, p1_1, ... (the data sets' pressure columns).")
      .def_prop_ro("num_pressures", [](const Robot& r) { return r.desc.num_inputs; }, "Number of pressure channels.")
      .def_prop_ro(
          "segment_names",
          [](const Robot& r) {
            std::vector<std::string> n;
            for (int i = 0; i < r.chain.num_segments(); ++i) n.push_back(r.chain.name(i));
            return n;
          },
          "Names of the bodies of the chain, base to tip (a payload effect adds one named 'payload'); "
          "one frame each in frames().")
      .def_prop_ro("gravity_vector", [](const Robot& r) { return vector_out(r.chain.gravity); }, 
                   "Gravitational acceleration in the base frame (m/s^2).")
      .def(
          "__reduce__",
          [](nb::handle self) {
            // Pickled as its description: Robot.from_dict(robot.to_dict()) (multiprocessing, Dask).
            // (A Python function: pickle cannot store nanobind's static methods by name.)
            return nb::make_tuple(nb::module_::import_("softrne").attr("_robot_from_dict"),
                                  nb::make_tuple(self.attr("to_dict")()));
          },
          "Pickles the robot as its description (Robot.from_dict of to_dict()).")
      .def("__repr__", [](const Robot& r) {
        return "softrne.Robot('" + r.desc.spec.name + "', nq=" + std::to_string(r.nq()) + ", segments=" +
               std::to_string(r.chain.num_segments()) + ")";
      });

  robot.def(
      "rnea",
      [](Robot& r, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& qdd, int threads) {
        const States s = states(r, "rnea", {{"q", q}, {"qd", qd}, {"qdd", qdd}});
        const int nq = r.nq();
        return evaluate(r, s, {static_cast<size_t>(nq)}, threads, [nq, &r](Data& d, const double* const* in, double* out) {
          Vec(out, nq) = softrne::rnea(r.chain, d, CVec(in[0], nq), CVec(in[1], nq), CVec(in[2], nq));
        });
      },
      "q"_a, "qd"_a, "qdd"_a, "threads"_a = 0,
      (std::string("Inverse dynamics by the recursive Newton-Euler algorithm: tau = M(q) qdd + C(q, qd) qd + "
                   "G(q), the generalised forces that inertia and gravity need (springs, dampers and "
                   "pressures excluded).") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "mass_matrix",
      [](Robot& r, const ArrayLike& q, int threads) {
        const States s = states(r, "mass_matrix", {{"q", q}});
        const int nq = r.nq();
        return evaluate(r, s, {static_cast<size_t>(nq), static_cast<size_t>(nq)}, threads,
                        [nq, &r](Data& d, const double* const* in, double* out) {
                          Eigen::Map<RowMatrix>(out, nq, nq) = softrne::mass_matrix(r.chain, d, CVec(in[0], nq));
                        });
      },
      "q"_a, "threads"_a = 0,
      (std::string("The joint-space mass matrix M(q), shape (nq, nq) (symmetric, positive definite).") + kThreadsDoc).c_str());
  robot.def(
      "gravity",
      [](Robot& r, const ArrayLike& q, int threads) {
        const States s = states(r, "gravity", {{"q", q}});
        const int nq = r.nq();
        return evaluate(r, s, {static_cast<size_t>(nq)}, threads, [nq, &r](Data& d, const double* const* in, double* out) {
          Vec(out, nq) = softrne::gravity(r.chain, d, CVec(in[0], nq));
        });
      },
      "q"_a, "threads"_a = 0,
      (std::string("The gravity forces G(q) = rnea(q, 0, 0) (the gravitational acceleration itself is "
                   "gravity_vector).") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "bias",
      [](Robot& r, const ArrayLike& q, const ArrayLike& qd, bool with_gravity, int threads) {
        const States s = states(r, "bias", {{"q", q}, {"qd", qd}});
        const int nq = r.nq();
        return evaluate(r, s, {static_cast<size_t>(nq)}, threads,
                        [nq, &r, with_gravity](Data& d, const double* const* in, double* out) {
                          Vec(out, nq) = softrne::bias(r.chain, d, CVec(in[0], nq), CVec(in[1], nq), with_gravity);
                        });
      },
      "q"_a, "qd"_a, "with_gravity"_a = false, "threads"_a = 0,
      (std::string("The velocity-product forces C(q, qd) qd = rnea(q, qd, 0) - G(q); with_gravity: "
                   "C(q, qd) qd + G(q) in one pass.") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "forward_dynamics",
      [](Robot& r, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& tau, int threads) {
        const States s = states(r, "forward_dynamics", {{"q", q}, {"qd", qd}, {"tau", tau}});
        const int nq = r.nq();
        return evaluate(r, s, {static_cast<size_t>(nq)}, threads, [nq, &r](Data& d, const double* const* in, double* out) {
          Vec(out, nq) = softrne::forward_dynamics(r.chain, d, CVec(in[0], nq), CVec(in[1], nq), CVec(in[2], nq));
        });
      },
      "q"_a, "qd"_a, "tau"_a, "threads"_a = 0,
      (std::string("Forward dynamics qdd = M(q)^-1 (tau - C(q, qd) qd - G(q)) by forming M and a Cholesky "
                   "solve; tau holds every other generalised force (pressures, springs, dampers). NaN "
                   "where M is not positive definite.") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "aba",
      [](Robot& r, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& tau, int threads) {
        const States s = states(r, "aba", {{"q", q}, {"qd", qd}, {"tau", tau}});
        const int nq = r.nq();
        return evaluate(r, s, {static_cast<size_t>(nq)}, threads, [nq, &r](Data& d, const double* const* in, double* out) {
          Vec(out, nq) = softrne::aba(r.chain, d, CVec(in[0], nq), CVec(in[1], nq), CVec(in[2], nq));
        });
      },
      "q"_a, "qd"_a, "tau"_a, "threads"_a = 0,
      (std::string("Forward dynamics in O(n) by the articulated-body recursion (same result as "
                   "forward_dynamics, without forming M).") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "rnea_derivatives",
      [](Robot& r, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& qdd, int threads) {
        const States s = states(r, "rnea_derivatives", {{"q", q}, {"qd", qd}, {"qdd", qdd}});
        const int nq = r.nq();
        const auto n = static_cast<size_t>(nq);
        return evaluate(r, s, {3, n, n}, threads, [nq, &r](Data& d, const double* const* in, double* out) {
          softrne::rnea_derivatives(r.chain, d, CVec(in[0], nq), CVec(in[1], nq), CVec(in[2], nq));
          Eigen::Map<RowMatrix>(out, nq, nq) = d.dtau_dq;
          Eigen::Map<RowMatrix>(out + nq * nq, nq, nq) = d.dtau_dqdot;
          Eigen::Map<RowMatrix>(out + 2 * nq * nq, nq, nq) = d.mass_matrix;
        });
      },
      "q"_a, "qd"_a, "qdd"_a, "threads"_a = 0,
      (std::string("The partial derivatives of rnea (softrne::rnea_derivatives, exact: world-frame composites "
                   "and AutoDiff on each perturbed CC segment), stacked as shape (3, nq, nq): d tau/d q, d tau/d qd, d tau/d qdd = M(q).") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "aba_derivatives",
      [](Robot& r, const ArrayLike& q, const ArrayLike& qd, const ArrayLike& tau, int threads) {
        const States s = states(r, "aba_derivatives", {{"q", q}, {"qd", qd}, {"tau", tau}});
        const int nq = r.nq();
        const auto n = static_cast<size_t>(nq);
        return evaluate(r, s, {3, n, n}, threads, [nq, &r](Data& d, const double* const* in, double* out) {
          softrne::aba_derivatives(r.chain, d, CVec(in[0], nq), CVec(in[1], nq), CVec(in[2], nq));
          Eigen::Map<RowMatrix>(out, nq, nq) = d.dqddot_dq;
          Eigen::Map<RowMatrix>(out + nq * nq, nq, nq) = d.dqddot_dqdot;
          Eigen::Map<RowMatrix>(out + 2 * nq * nq, nq, nq) = d.dqddot_dtau;
        });
      },
      "q"_a, "qd"_a, "tau"_a, "threads"_a = 0,
      (std::string("The partial derivatives of forward dynamics (softrne::aba_derivatives, exact), stacked as "
                   "shape (3, nq, nq): d qdd/d q, d qdd/d qd, d qdd/d tau = M(q)^-1.") +
       kThreadsDoc)
          .c_str());
  robot.def(
      "frames",
      [](Robot& r, const ArrayLike& q, int threads) {
        const States s = states(r, "frames", {{"q", q}});
        const int nq = r.nq();
        const size_t nseg = static_cast<size_t>(r.chain.num_segments());
        return evaluate(r, s, {nseg, 4, 4}, threads, [nq, nseg, &r](Data& d, const double* const* in, double* out) {
          d.qdot_zero.setZero();
          softrne::compute_kinematics(r.chain, d, CVec(in[0], nq), d.qdot_zero);
          for (size_t i = 0; i < nseg; ++i) {
            const auto X = softrne::distal_placement(r.chain, d, static_cast<int>(i));
            Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> T(out + 16 * i);
            T.setIdentity();
            T.topLeftCorner<3, 3>() = X.R;
            T.topRightCorner<3, 1>() = X.p;
          }
        });
      },
      "q"_a, "threads"_a = 0,
      (std::string("Poses of the distal frame of every segment in the base frame at configuration q, "
                   "shape (segments, 4, 4) (homogeneous transforms, base to tip: segment_names); for "
                   "drawing the arm.") +
       kThreadsDoc)
          .c_str());


  // ---- the state equation, its linearisation -----------------------------------------------
  robot.def_prop_ro("num_states", [](const Robot& r) { return r.desc.num_states(); },
                    "Number of states n of the simulated arm: x = [q (nq), qd (nq), the effects' internal "
                    "states] (2 nq when the robot has no effect with states).");
  robot.def(
      "initial_state",
      [](const Robot& r, const ArrayLike& q0, const ArrayLike& p0) {
        const Eigen::VectorXd q =
            q0.is_none() ? Eigen::VectorXd() : robot_vector(q0, "initial_state", "q0", r.desc.nq, "coordinates");
        const Eigen::VectorXd p = p0.is_none() ? Eigen::VectorXd::Zero(r.desc.num_inputs)
                                               : robot_vector(p0, "initial_state", "p0", r.desc.num_inputs, "pressures");
        return vector_out(softrne::initial_state(r.desc, q, p));
      },
      "q0"_a = nb::none(), "p0"_a = nb::none(),
      "The state (num_states,) a simulation starts from: at rest at the measured angles q0 (nq,) (the "
      "measurement model inverted; None: q = 0), the effects' states at rest under the pressures p0 "
      "(num_pressures,) (None: 0 Pa), as simulate and simulate_closed_loop start.");
  robot.def(
      "state_derivative",
      [](const Robot& r, const ArrayLike& x, const ArrayLike& p) {
        const Eigen::VectorXd xv = robot_vector(x, "state_derivative", "x", r.desc.num_states(), "states");
        const Eigen::VectorXd pv = robot_vector(p, "state_derivative", "p", r.desc.num_inputs, "pressures");
        sim::ArmJacobian f(r.desc);
        Eigen::VectorXd xdot(xv.size());
        f.rhs(xv, pv, xdot);
        return vector_out(xdot);
      },
      "x"_a, "p"_a,
      "The simulator's state equation f(x, p) = dx/dt (eq. 23 with the springs, dampers, pressures and "
      "effects; sim::ArmJacobian::rhs) at the state x (num_states,) and the chamber pressures p "
      "(num_pressures,), Pa. NaN where it is not defined (M not positive definite). A transport delay "
      "(input_delay effect) is not part of f.");
  robot.def(
      "linearise",
      [](const Robot& r, const ArrayLike& x, const ArrayLike& p) {
        const Eigen::VectorXd xv = robot_vector(x, "linearise", "x", r.desc.num_states(), "states");
        const Eigen::VectorXd pv = robot_vector(p, "linearise", "p", r.desc.num_inputs, "pressures");
        try {
          return sim::linearise(r.desc, xv, pv);
        } catch (const std::invalid_argument& e) {
          throw nb::value_error((std::string("softrne.") + e.what()).c_str());
        }
      },
      "x"_a, "p"_a,
      "The linearisation of the state equation at (x, p) (sim::linearise): A = df/dx (n, n) and B = "
      "df/dp (n, num_pressures), exact (forward-mode AutoDiff), and f = f(x, p), so that near (x, p) "
      "d(dx)/dt = f + A dx + B dp. Raises ValueError if f or its derivatives are not finite there.");
  robot.def(
      "static_equilibrium",
      [](const Robot& r, const ArrayLike& p, const ArrayLike& q_guess) {
        const Eigen::VectorXd pv = robot_vector(p, "static_equilibrium", "p", r.desc.num_inputs, "pressures");
        const Eigen::VectorXd q0 = q_guess.is_none()
                                       ? Eigen::VectorXd()
                                       : robot_vector(q_guess, "static_equilibrium", "q_guess", r.desc.nq, "coordinates");
        try {
          return vector_out(softrne::rest_state(r.desc, softrne::static_equilibrium(r.desc, pv, q0), pv));
        } catch (const std::runtime_error& e) {
          throw nb::value_error((std::string("softrne.Robot.static_equilibrium: ") + e.what()).c_str());
        }
      },
      "p"_a, "q_guess"_a = nb::none(),
      "The state x (num_states,) at which the arm rests under the chamber pressures p (num_pressures,), Pa: "
      "f(x, p) = 0 with qd = 0 and the effects' states at rest there (softrne::static_equilibrium, a damped "
      "Newton from q_guess (nq,) coordinates, None: the straight arm). Raises ValueError if it finds none.");

  // ---- data sets -------------------------------------------------------------------------
  nb::class_<softrne::io::Dataset>(m, "Dataset",
                                   "A data set (docs/formats.md section 2): time, chamber pressures and "
                                   "optionally measured angles, in the robot's column order.")
      .def(
          "__init__",
          [](softrne::io::Dataset* self, const Robot& r, const ArrayLike& t, const ArrayLike& pressures, const ArrayLike& angles,
             const std::string& source) {
            new (self) softrne::io::Dataset(dataset_from_arrays(r, t, pressures, angles, source));
          },
          "robot"_a, "t"_a, "pressures"_a, "angles"_a = nb::none(), "source"_a = "<arrays>",
          "A data set for `robot` from arrays: t (N,), pressures (N, num_pressures), angles (N, nq) or None.")
      .def_prop_ro("t", [](const softrne::io::Dataset& d) { return vector_out(d.t); },  "Sample times (s), shape (N,).")
      .def_prop_ro("pressures", [](const softrne::io::Dataset& d) { return matrix_out(d.pressures); }, 
                   "Chamber pressures (Pa), shape (N, num_pressures).")
      .def_prop_ro(
          "angles",
          [](const softrne::io::Dataset& d) -> nb::object {
            if (!d.has_angles) return nb::none();
            return matrix_out(d.angles);
          },
          "Measured angles (rad), shape (N, nq), or None.")
      .def_ro("has_angles", &softrne::io::Dataset::has_angles)
      .def_ro("pressure_names", &softrne::io::Dataset::pressure_names)
      .def_ro("angle_names", &softrne::io::Dataset::angle_names)
      .def_ro("source", &softrne::io::Dataset::source, "The file it was read from (for messages).")
      .def("__len__", [](const softrne::io::Dataset& d) { return static_cast<size_t>(d.t.size()); })
      .def("__repr__", [](const softrne::io::Dataset& d) {
        return "softrne.Dataset('" + d.source + "', " + std::to_string(d.t.size()) + " samples" +
               (d.has_angles ? ", with angles)" : ", no angles)");
      });

  m.def(
      "read_dataset",
      [](const std::filesystem::path& path, const Robot& r, bool require_angles) {
        return softrne::io::read_dataset(path.string(), softrne::to_robot_spec(r.desc), require_angles);
      },
      "path"_a, "robot"_a, "require_angles"_a = false,
      "Reads a data set CSV for `robot` (softrne's reader: columns t, p{j}_{k}, u{j}, v{j}). Raises "
      "InputError naming the file, line and column.");
  m.def(
      "write_dataset",
      [](const std::filesystem::path& path, const Robot& r, const ArrayLike& t, const ArrayLike& pressures, const ArrayLike& angles) {
        const Eigen::VectorXd tv = vector_in(t, "write_dataset", "t");
        const Eigen::Index N = tv.size();
        std::vector<Eigen::MatrixXd> blocks;
        softrne::io::Table table;
        table.header.push_back("t");
        Eigen::Index cols = 1;
        if (!pressures.is_none()) {
          blocks.push_back(matrix_in(pressures, "write_dataset", "pressures", N, r.desc.num_inputs));
          table.header.insert(table.header.end(), r.desc.pressure_names.begin(), r.desc.pressure_names.end());
          cols += r.desc.num_inputs;
        }
        if (!angles.is_none()) {
          blocks.push_back(matrix_in(angles, "write_dataset", "angles", N, r.desc.nq));
          table.header.insert(table.header.end(), r.desc.coordinate_names.begin(), r.desc.coordinate_names.end());
          cols += r.desc.nq;
        }
        table.values.resize(N, cols);
        table.values.col(0) = tv;
        Eigen::Index c = 1;
        for (const auto& b : blocks) {
          table.values.middleCols(c, b.cols()) = b;
          c += b.cols();
        }
        softrne::io::write_csv(path.string(), table);
      },
      "path"_a, "robot"_a, "t"_a, "pressures"_a = nb::none(), "angles"_a = nb::none(),
      "Writes a data set CSV (softrne's writer: t, then the pressure and angle columns given, "
      "numbers in shortest round-trip form, so read_dataset reads back the same doubles).");

  // ---- simulation, fit, loop -------------------------------------------------------------
  m.def(
      "simulate",
      [](const Robot& r, const ArrayLike& t, const ArrayLike& pressures, const ArrayLike& q0, const nb::kwargs& kw) {
        const Eigen::VectorXd tv = vector_in(t, "simulate", "t");
        if (tv.size() < 2) throw nb::value_error("softrne.simulate: t needs at least 2 samples");
        const Eigen::MatrixXd p = matrix_in(pressures, "simulate", "pressures", tv.size(), r.desc.num_inputs);
        const Eigen::VectorXd q = q0.is_none() ? Eigen::VectorXd::Zero(r.desc.nq) : vector_in(q0, "simulate", "q0", r.desc.nq);
        softrne::sim::ArmSimulationOptions opt = simulation_options(kw, tv(0), tv(tv.size() - 1));
        const softrne::sim::ArmSimulation sim = run_interruptible([&](const std::atomic<bool>& stop) {
          opt.cvode.stop = &stop;
          return softrne::sim::simulate_arm(r.desc, tv, p, q, opt);
        });
        if (!sim.ok()) throw softrne::cli::Failure("softrne.simulate: " + sim.result.message);
        return matrix_out(sim.angles);
      },
      "robot"_a, "t"_a, "pressures"_a, "q0"_a = nb::none(), "solver_options"_a,
      "Simulates the arm from rest at q0 (measured angles; None: zero) under the recorded chamber "
      "pressures (N, num_pressures) on the time grid t (N,), with CVODE exactly as softrne-sim does "
      "(BDF, AutoDiff Jacobian, pchip interpolation of the pressures, restarts at pressure jumps). "
      "Returns the measured-space angles, shape (N, nq).\n\nSolver options (softrne-sim's, same "
      "defaults): rtol (1e-6), atol (1e-5 rad), atol_velocity (1000 atol = 1e-2 rad/s), interpolation ('pchip', "
      "'linear', 'zoh'), smooth (seconds of Gaussian pre-smoothing; off), jacobian ('ad', "
      "'ad-forward', 'fd'), max_steps (max(1e5, 1e4 per s)), max_wall_seconds. Raises "
      "SimulationError if the integration fails.");

  // ---- linearisation and control in the loop ----------------------------------------------
  nb::class_<sim::Linearisation>(m, "Linearisation",
                                 "The continuous linearisation of x' = f(x, p) at (x, p) (Robot.linearise): "
                                 "d(dx)/dt = f + A dx + B dp.")
      .def_prop_ro("x", [](const sim::Linearisation& l) { return vector_out(l.x); }, "The state it was taken at, (n,).")
      .def_prop_ro("p", [](const sim::Linearisation& l) { return vector_out(l.p); },
                   "The pressures it was taken at, Pa, (num_pressures,).")
      .def_prop_ro("f", [](const sim::Linearisation& l) { return vector_out(l.f); },
                   "f(x, p), (n,): zero at an equilibrium.")
      .def_prop_ro("A", [](const sim::Linearisation& l) { return matrix_out(l.A); }, "df/dx, (n, n).")
      .def_prop_ro("B", [](const sim::Linearisation& l) { return matrix_out(l.B); },
                   "df/dp, (n, num_pressures) (1/s per Pa in the velocity rows).")
      .def(
          "discretise_zoh",
          [](const sim::Linearisation& l, double h) {
            check_sample_time(h, "Linearisation.discretise_zoh");
            return sim::discretise_zoh(l, h);
          },
          "h"_a,
          "The zero-order-hold discretisation for the sample time h (s) (sim::discretise_zoh): dx_k+1 = "
          "Ad dx_k + Bd dp_k + cd, from the exponential of [[A, B, f], [0, 0, 0]] h.")
      .def("__repr__", [](const sim::Linearisation& l) {
        return "softrne.Linearisation(n=" + std::to_string(l.A.rows()) + ", num_pressures=" + std::to_string(l.B.cols()) +
               ", |f|=" + number_text(l.f.norm()) + ")";
      });

  nb::class_<sim::DiscreteLinearisation>(m, "DiscreteLinearisation",
                                         "A zero-order-hold discretisation: dx_k+1 = Ad dx_k + Bd dp_k + cd over "
                                         "a sample time h. Unpacks as Ad, Bd, cd = ...")
      .def_ro("h", &sim::DiscreteLinearisation::h, "The sample time, s.")
      .def_prop_ro("Ad", [](const sim::DiscreteLinearisation& d) { return matrix_out(d.Ad); }, "exp(A h), (n, n).")
      .def_prop_ro("Bd", [](const sim::DiscreteLinearisation& d) { return matrix_out(d.Bd); },
                   "The integral of exp(A s) ds over [0, h] times B, (n, m).")
      .def_prop_ro("cd", [](const sim::DiscreteLinearisation& d) { return vector_out(d.cd); },
                   "The integral of exp(A s) ds over [0, h] times f, (n,): the drift off an equilibrium "
                   "(0 at one).")
      .def("__iter__",
           [](const sim::DiscreteLinearisation& d) {
             return nb::iter(nb::make_tuple(matrix_out(d.Ad), matrix_out(d.Bd), vector_out(d.cd)));
           })
      .def("__repr__", [](const sim::DiscreteLinearisation& d) {
        return "softrne.DiscreteLinearisation(h=" + number_text(d.h) + ", n=" + std::to_string(d.Ad.rows()) +
               ", m=" + std::to_string(d.Bd.cols()) + ")";
      });

  m.def(
      "discretise_zoh",
      [](const ArrayLike& A, const ArrayLike& B, double h, const ArrayLike& f) {
        const char* fn = "discretise_zoh";
        const Array a = as_array(A, fn, "A");
        if (a.ndim() != 2 || a.shape(0) != a.shape(1))
          throw nb::value_error(("softrne.discretise_zoh: A has shape " + shape_text(a) + "; expected a square (n, n)").c_str());
        const auto n = static_cast<Eigen::Index>(a.shape(0));
        const Array b = as_array(B, fn, "B");
        if (b.ndim() != 2 || static_cast<Eigen::Index>(b.shape(0)) != n)
          throw nb::value_error(("softrne.discretise_zoh: B has shape " + shape_text(b) + "; A has " +
                                 std::to_string(n) + " rows: expected (" + std::to_string(n) + ", m)")
                                    .c_str());
        check_sample_time(h, fn);
        sim::Linearisation l;
        l.A = Eigen::Map<const RowMatrix>(a.data(), n, n);
        l.B = Eigen::Map<const RowMatrix>(b.data(), n, static_cast<Eigen::Index>(b.shape(1)));
        l.f = f.is_none() ? Eigen::VectorXd::Zero(n) : vector_in(f, fn, "f", n);
        const char* bad = !l.A.allFinite() ? "A" : !l.B.allFinite() ? "B" : !l.f.allFinite() ? "f" : nullptr;
        if (bad) throw nb::value_error(("softrne.discretise_zoh: " + std::string(bad) + " is not finite").c_str());
        return sim::discretise_zoh(l, h);
      },
      "A"_a, "B"_a, "h"_a, "f"_a = nb::none(),
      "The zero-order-hold discretisation of x' = A x + B u + f for the sample time h (s): "
      "x_k+1 = Ad x_k + Bd u_k + cd, by the exponential of the augmented matrix [[A, B, f], [0, 0, 0]] h "
      "(Van Loan; sim::discretise_zoh). f None: 0 (then cd = 0). Returns a DiscreteLinearisation "
      "(Ad, Bd, cd = ... unpacks it).");

  nb::class_<ControllerObservation>(m, "ControllerInput",
                                    "What a controller of simulate_closed_loop sees at sample k (new arrays "
                                    "at every sample).")
      .def_ro("k", &ControllerObservation::k, "The sample index: t = k * control_period.")
      .def_ro("t", &ControllerObservation::t, "The time, s.")
      .def_ro("angles", &ControllerObservation::angles,
              "The measured angles (nq,), rad: the sensors' gain .* q + offset (what simulate returns).")
      .def_ro("velocities", &ControllerObservation::velocities, "Their rates (nq,), rad/s: gain .* qd.")
      .def_ro("state", &ControllerObservation::state,
              "The simulator's whole state (num_states,) [q, qd, effect states], for designs that assume "
              "full-state knowledge (Robot.linearise's x).")
      .def("__repr__", [](const ControllerObservation& o) {
        return "softrne.ControllerInput(k=" + std::to_string(o.k) + ", t=" + number_text(o.t) + ")";
      });

  nb::class_<sim::ClosedLoopSimulation>(m, "ClosedLoopSimulation",
                                        "A run of simulate_closed_loop on the sample grid t_k = k * "
                                        "control_period, k = 0..N (fewer rows if it failed).")
      .def_prop_ro("t", [](const sim::ClosedLoopSimulation& s) { return vector_out(s.t); }, "The sample times (N + 1,), s.")
      .def_prop_ro("states", [](const sim::ClosedLoopSimulation& s) { return matrix_out(s.states); },
                   "The state at each sample, (N + 1, num_states).")
      .def_prop_ro("angles", [](const sim::ClosedLoopSimulation& s) { return matrix_out(s.angles); },
                   "The measured angles the controller saw, (N + 1, nq), rad.")
      .def_prop_ro("commands", [](const sim::ClosedLoopSimulation& s) { return matrix_out(s.commands); },
                   "The controller's outputs clamped to [p_min, p_max], (N + 1, num_pressures), Pa.")
      .def_prop_ro("pressures", [](const sim::ClosedLoopSimulation& s) { return matrix_out(s.pressures); },
                   "The pressures held over [t_k, t_k+1): the commands delayed by delay_periods "
                   "(initial_pressures before), (N + 1, num_pressures), Pa; row N acts after the run. "
                   "simulate(robot, t, pressures, q0, interpolation='zoh') replays the run open loop.")
      .def_prop_ro("ok", &sim::ClosedLoopSimulation::ok, "True if the run reached the last sample.")
      .def_prop_ro("message", [](const sim::ClosedLoopSimulation& s) { return s.result.message; },
                   "'' if ok; else the one-line reason and the time reached.")
      .def_prop_ro("t_reached", [](const sim::ClosedLoopSimulation& s) { return s.result.t_reached; },
                   "The last time the solution is known at, s.")
      .def_prop_ro("stats", [](const sim::ClosedLoopSimulation& s) { return stats_dict(s.result.stats); },
                   "The solver's counters over the run: steps, rhs_evals, jac_evals, "
                   "rhs_evals_for_jacobian_fd, error_test_failures, nonlinear_convergence_failures, "
                   "restarts (one per sample inside the run: N - 1), wall_seconds.")
      .def("__len__", [](const sim::ClosedLoopSimulation& s) { return static_cast<size_t>(s.t.size()); })
      .def("__repr__", [](const sim::ClosedLoopSimulation& s) {
        return "softrne.ClosedLoopSimulation(" + std::to_string(s.t.size()) + " samples, " +
               (s.ok() ? std::string("ok") : "failed: " + s.result.message) + ")";
      });

  m.def(
      "simulate_closed_loop",
      [](const Robot& r, const ControllerFunction& controller, double t_end, double control_period, const ArrayLike& q0,
         int delay_periods, double p_min, double p_max, const ArrayLike& initial_pressures, bool check,
         const nb::kwargs& kw) {
        const char* fn = "simulate_closed_loop";
        const std::string prefix = "softrne.simulate_closed_loop: ";
        if (!PyCallable_Check(controller.ptr())) throw nb::type_error((prefix + "controller is not callable").c_str());
        if (!(control_period > 0) || !std::isfinite(control_period))
          throw nb::value_error((prefix + "control_period must be positive and finite (got " + number_text(control_period) + ")").c_str());
        if (!(t_end > 0) || !std::isfinite(t_end))
          throw nb::value_error((prefix + "t_end must be positive and finite (got " + number_text(t_end) + ")").c_str());
        if (t_end / control_period > 1e8) throw nb::value_error((prefix + "more than 1e8 control periods").c_str());
        if (delay_periods < 0)
          throw nb::value_error((prefix + "delay_periods must be >= 0 (got " + std::to_string(delay_periods) + ")").c_str());
        if (std::isnan(p_min) || std::isnan(p_max) || !(p_min <= p_max))
          throw nb::value_error((prefix + "p_min (" + number_text(p_min) + ") must not exceed p_max (" + number_text(p_max) + ")").c_str());
        const Eigen::VectorXd q = q0.is_none() ? Eigen::VectorXd() : robot_vector(q0, fn, "q0", r.desc.nq, "coordinates");
        sim::ClosedLoopOptions opt;
        if (!initial_pressures.is_none()) {
          opt.initial_pressures = robot_vector(initial_pressures, fn, "initial_pressures", r.desc.num_inputs, "pressures");
          if (!opt.initial_pressures.allFinite()) throw nb::value_error((prefix + "initial_pressures are not finite").c_str());
        }
        opt.delay_periods = delay_periods;
        opt.p_min = p_min;
        opt.p_max = p_max;
        const double periods = std::max(1.0, std::ceil(t_end / control_period - 1e-9));
        opt.simulation = simulation_options(kw, 0.0, periods * control_period, fn, true);

        // The controller runs with the GIL (the integration runs without it). A Python
        // exception it raises (or a bad return value) is kept and raised again here, after
        // the run, as itself; the C++ loop sees a ControllerError and stops at that sample.
        std::optional<nb::python_error> raised;
        const sim::Controller c = [&](const sim::ControllerInput& in) -> Eigen::VectorXd {
          nb::gil_scoped_acquire gil;
          try {
            nb::object ret = controller(nb::cast(ControllerObservation{in.k, in.t, vector_out(in.angles),
                                                                       vector_out(in.velocities), vector_out(in.state)}));
            return controller_pressures(r, ret, in);
          } catch (nb::python_error& e) {
            raised.emplace(std::move(e));
          }
          throw std::runtime_error("the Python controller raised an exception");
        };
        sim::ClosedLoopSimulation res = run_interruptible([&](const std::atomic<bool>& stop) {
          opt.simulation.cvode.stop = &stop;
          return sim::simulate_closed_loop(r.desc, c, q, t_end, control_period, opt);
        });
        if (raised) throw nb::python_error(std::move(*raised));
        if (!res.ok()) {
          if (res.result.message.rfind("invalid arguments: ", 0) == 0)
            throw nb::value_error((prefix + res.result.message.substr(19)).c_str());
          if (check) throw softrne::cli::Failure(prefix + res.result.message);
        }
        return res;
      },
      "robot"_a, "controller"_a, "t_end"_a, "control_period"_a, "q0"_a = nb::none(), nb::kw_only(),
      "delay_periods"_a = 0, "p_min"_a = 0.0, "p_max"_a = std::numeric_limits<double>::infinity(),
      "initial_pressures"_a = nb::none(), "check"_a = true, "solver_options"_a,
      "Simulates the arm under a controller sampled every control_period seconds from t = 0 to the first "
      "sample at or after t_end (sim::simulate_closed_loop), starting at rest at the measured angles q0 "
      "(None: 0) under initial_pressures.\n\n"
      "At each sample t_k = k control_period, controller(s) is called with s a ControllerInput: s.k, "
      "s.t, s.angles (nq,) and s.velocities (nq,) (measured), s.state (num_states,). It returns the "
      "num_pressures chamber pressures (Pa, array-like of shape (num_pressures,)); they are clamped to "
      "[p_min, p_max] and held (zero-order hold) over one period, delay_periods samples later "
      "(initial_pressures, default 0 Pa and clamped too, act before and set the effects' initial "
      "states). The integrator (CVODE BDF, AutoDiff Jacobian) restarts at every sample and runs "
      "without the GIL; the controller runs with it.\n\n"
      "Returns a ClosedLoopSimulation (t, states, angles, commands, pressures, ok, message, stats). An "
      "exception the controller raises propagates unchanged; a return value of the wrong shape or a "
      "non-finite pressure raises ValueError (None: TypeError) naming the sample. An integration that "
      "fails raises SimulationError, or with check=False returns the samples before the failure with "
      "ok False and the message. Solver options: rtol, atol, atol_velocity, jacobian, max_steps, "
      "max_wall_seconds as for simulate (interpolation and smooth do not apply).");

  m.def(
      "_stack_recordings",
      [](const std::vector<softrne::io::Dataset>& parts, const std::string& initial_motion) {
        if (initial_motion != "rest" && initial_motion != "estimated")
          throw nb::value_error(("softrne: initial_motion must be 'rest' or 'estimated', not '" + initial_motion + "'").c_str());
        try {
          softrne::io::Dataset d = softrne::io::stack_recordings(parts);
          if (initial_motion == "estimated") softrne::io::estimate_initial_rates(d);
          return d;
        } catch (const std::invalid_argument& e) {
          throw nb::value_error(e.what());
        }
      },
      "parts"_a, "initial_motion"_a,
      "Several recordings as one data set (io::stack_recordings), each simulated from its own first "
      "sample; 'estimated': at the angle rates of its first 9 samples.");
  m.def(
      "_fit",
      [](const Robot& r, const softrne::io::Dataset& train, const softrne::io::Dataset* test, bool pressure_gain,
         unsigned seed, int threads, const std::string& fit_to, bool frame_per_recording) {
        softrne::fit::ArmFitOptions opt;
        opt.pressure_gain = pressure_gain;
        opt.optimiser.seed = seed;
        opt.optimiser.threads = std::max(1, threads);
        opt.capture_frame_per_recording = frame_per_recording;
        if (fit_to != "all" && fit_to != "angles" && fit_to != "markers")
          throw nb::value_error(("softrne.fit: fit_to must be 'all', 'angles' or 'markers', not '" + fit_to + "'").c_str());
        const nlohmann::ordered_json report = run_interruptible([&](const std::atomic<bool>& stop) {
          opt.simulation.cvode.stop = &stop;
          nlohmann::ordered_json j = softrne::cli::fit_report_json(softrne::cli::run_fit(r.desc, train, test, opt, fit_to));
          softrne::cli::add_recordings(j, train, test);
          return j;
        });
        return to_python(report);
      },
      "robot"_a, "train"_a, "test"_a.none(), "pressure_gain"_a, "seed"_a, "threads"_a, "fit_to"_a,
      "frame_per_recording"_a);
  m.def(
      "_loop",
      [](const Robot& r, const softrne::io::Dataset& train, const softrne::io::Dataset& test, int threads,
         int max_effects, nb::object log) {
        softrne::fit::LoopOptions opt;
        opt.fit.optimiser.threads = std::max(1, threads);
        opt.max_effects = max_effects;
        if (!log.is_none())
          opt.log = [&log](const std::string& line) {
            nb::gil_scoped_acquire gil;
            log(line);
          };
        const softrne::fit::LoopResult res = run_interruptible([&](const std::atomic<bool>& stop) {
          opt.fit.simulation.cvode.stop = &stop;
          try {
            return softrne::fit::run_loop(r.desc, train, &test, opt);
          } catch (const std::invalid_argument& e) {
            throw softrne::cli::Failure(e.what());
          }
        });
        nlohmann::ordered_json report = softrne::cli::loop_report_json(res, true, opt);
        const std::vector<softrne::cli::RecordingMedians> medians = softrne::cli::loop_test_medians(res, test);
        softrne::cli::add_recordings(report, train, &test, &medians);
        return to_python(report);
      },
      "robot"_a, "train"_a, "test"_a, "threads"_a, "max_effects"_a, "log"_a.none());
}

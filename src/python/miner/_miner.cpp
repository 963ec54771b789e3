// Python bindings of MINER (REQ-LIB-002): maps, heuristic regions (sGAN and A* oracle), the
// RRT* family, MINCO, scenarios and closed-loop flights, with numpy arrays in and out.
// `import miner` (src/python/miner/__init__.py) re-exports this module, `_miner`.
//
// Errors: miner::Error (bad input, naming the field) becomes miner.Error, a ValueError;
// miner::NoSolution becomes miner.NoSolution. Long calls (planning, flight) release the GIL.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/text.hpp"
#include "miner/core/units.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/scenario.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/reference.hpp"
#include "miner/plan/rrt_star.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/time_allocation.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"
#include "miner/world/map.hpp"
#include "miner/world/map_generator.hpp"

namespace py = pybind11;
using miner::Json;
using V3 = Eigen::Vector3d;

namespace {

/// The poll of a long plan or flight: with the GIL held, raise what Python has pending (Ctrl-C's
/// KeyboardInterrupt) through the C++ call (eleventh campaign P1: a SIGINT waited for the whole
/// budget, ~40 s, and the result was then thrown away).
void python_signals() {
  py::gil_scoped_acquire locked;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

// ---------------------------------------------------------------- argument checks
// Every argument is taken as a Python object and converted here, so a wrong type or value is a
// miner.Error naming the argument (REQ-LIB-002), never pybind11's "incompatible function
// arguments" with the whole signature, a wrapped integer or a silent NaN (issue 20, ninth
// campaign P4, P9, P11, P14, P15). Ranges are the CLI's and the file formats'.

std::string type_name(py::handle o) { return py::str(py::type::of(o).attr("__name__")); }

py::module_ numpy() { return py::module_::import("numpy"); }

bool is_bool(py::handle o) {
  return py::isinstance<py::bool_>(o) || py::isinstance(o, numpy().attr("bool_"));
}

/// An int or a numpy integer (never a bool, a float or a string).
bool is_integer(py::handle o) {
  return !is_bool(o) && (PyLong_Check(o.ptr()) || py::isinstance(o, numpy().attr("integer")));
}

/// A real number: an int, a float or a numpy integer/floating (never a bool, complex or string).
double number(py::handle o, const std::string& field) {
  if (is_bool(o) || !(is_integer(o) || PyFloat_Check(o.ptr()) || py::isinstance(o, numpy().attr("floating"))))
    throw miner::Error(field + ": expected a number, got " + (o.is_none() ? std::string("None") : type_name(o)));
  const double v = PyFloat_AsDouble(o.ptr());
  if (PyErr_Occurred()) {
    PyErr_Clear();
    throw miner::Error(field + ": " + std::string(py::str(o)) + " is beyond the largest double");
  }
  return v;
}

double finite_number(py::handle o, const std::string& field) {
  const double v = number(o, field);
  if (!std::isfinite(v)) throw miner::Error(field + ": must be a finite number, got " + miner::short_number(v));
  return v;
}

double number_in(py::handle o, const std::string& field, double lo, double hi, const std::string& unit = "") {
  const double v = finite_number(o, field);
  if (v < lo || v > hi)
    throw miner::Error(field + ": must be in [" + miner::short_number(lo) + ", " + miner::short_number(hi) + "]" +
                       (unit.empty() ? "" : " " + unit) + ", got " + miner::short_number(v));
  return v;
}

/// A float holding a whole number (8.0, numpy's float64(8)), read as that integer.
bool is_whole_float(py::handle o) {
  if (is_bool(o) || !(PyFloat_Check(o.ptr()) || py::isinstance(o, numpy().attr("floating")))) return false;
  const double v = PyFloat_AsDouble(o.ptr());
  return std::isfinite(v) && std::floor(v) == v && std::fabs(v) < 9007199254740992.0;  // 2^53: exact
}

/// An integer in [lo, hi], checked on Python's own (unbounded) integer before any C++ cast; a
/// whole float (dims computed with numpy) is that integer, a fractional one is refused.
long long integer_in(py::handle o, const std::string& field, long long lo, long long hi) {
  if (is_whole_float(o)) {
    const double v = PyFloat_AsDouble(o.ptr());
    if (v < static_cast<double>(lo) || v > static_cast<double>(hi))
      throw miner::Error(field + ": must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "], got " + miner::short_number(v));
    return static_cast<long long>(v);
  }
  if (!is_integer(o))
    throw miner::Error(field + ": expected an integer, got " + (o.is_none() ? std::string("None") : type_name(o)) +
                       (PyFloat_Check(o.ptr()) ? " " + std::string(py::str(o)) : std::string()));
  const py::int_ v = py::reinterpret_steal<py::int_>(PyNumber_Index(o.ptr()));
  if (v < py::int_(lo) || v > py::int_(hi))
    throw miner::Error(field + ": must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                       std::string(py::str(py::handle(v))));
  return v.cast<long long>();
}

std::uint64_t seed_of(py::handle o, const std::string& field = "seed") {
  // The integer rule of every argument: a whole float that holds its integer exactly (below
  // 2^53) is that integer (seventeenth campaign F19: iterations=300.0 passed, seed=1.0 did not).
  if (is_whole_float(o)) {
    const double v = PyFloat_AsDouble(o.ptr());
    if (v < 0.0) throw miner::Error(field + ": must be an integer in [0, 2^64 - 1], got " + miner::short_number(v));
    return static_cast<std::uint64_t>(v);
  }
  if (!is_integer(o))
    throw miner::Error(field + ": expected an integer in [0, 2^64 - 1], got " + type_name(o) +
                       (PyFloat_Check(o.ptr()) ? " " + std::string(py::str(o)) +
                                                     " (a float is taken as an integer only when whole and below 2^53)"
                                               : std::string()));
  const py::int_ v = py::reinterpret_steal<py::int_>(PyNumber_Index(o.ptr()));
  if (v < py::int_(0) || v > py::int_(py::reinterpret_steal<py::object>(PyLong_FromUnsignedLongLong(~0ULL))))
    throw miner::Error(field + ": must be an integer in [0, 2^64 - 1], got " + std::string(py::str(py::handle(v))));
  return v.cast<std::uint64_t>();
}

bool flag(py::handle o, const std::string& field) {
  if (!is_bool(o)) throw miner::Error(field + ": expected True or False, got " + type_name(o));
  return PyObject_IsTrue(o.ptr()) == 1;
}

/// A real array: a numpy array or a (nested) sequence of ints and floats; not bool, complex,
/// object or string data.
py::array_t<double> real_array(py::handle o, const std::string& field) {
  py::object a;
  try {
    a = numpy().attr("asarray")(o);
  } catch (const py::error_already_set&) {
    throw miner::Error(field + ": expected an array of numbers, got " + type_name(o));
  }
  const std::string kind = py::str(a.attr("dtype").attr("kind"));
  if (kind != "i" && kind != "u" && kind != "f")
    throw miner::Error(field + ": expected an array of numbers, got " + type_name(o) + " of dtype " +
                       std::string(py::str(a.attr("dtype"))));
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

/// (n, 3) rows of finite points.
Eigen::MatrixX3d points_of(py::handle o, const std::string& field) {
  const py::array_t<double> a = real_array(o, field);
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw miner::Error(field + ": expected an (n, 3) array, got shape " + std::string(py::str(py::object(a.attr("shape")))));
  Eigen::MatrixX3d m(a.shape(0), 3);
  const auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (py::ssize_t k = 0; k < 3; ++k) {
      m(i, k) = r(i, k);
      if (!std::isfinite(m(i, k)))
        throw miner::Error(field + "[" + std::to_string(i) + "]: must be finite, got " + miner::short_number(m(i, k)));
    }
  return m;
}

V3 point_of(py::handle o, const std::string& field) {
  const py::array_t<double> a = real_array(o, field);
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw miner::Error(field + ": expected 3 coordinates, got shape " + std::string(py::str(py::object(a.attr("shape")))));
  const V3 p(a.at(0), a.at(1), a.at(2));
  miner::require_finite(p, field);
  return p;
}

std::optional<V3> optional_point(py::handle o, const std::string& field) {
  if (o.is_none()) return std::nullopt;
  return point_of(o, field);
}

/// A 1-D array of numbers (NaN left to the caller, which names its index).
std::vector<double> vector_of(py::handle o, const std::string& field) {
  const py::array_t<double> a = real_array(o, field);
  if (a.ndim() != 1) throw miner::Error(field + ": expected a 1-D array, got " + std::to_string(a.ndim()) + " dimensions");
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

/// A file path: a str or an os.PathLike, non-UTF-8 names as os.fsencode gives them; not empty.
std::string path_of(py::handle o, const std::string& field) {
  py::object p;
  try {
    p = py::module_::import("os").attr("fsencode")(o);
  } catch (const py::error_already_set&) {
    throw miner::Error(field + ": expected a path (str or os.PathLike), got " + type_name(o));
  }
  std::string s = py::cast<std::string>(py::bytes(p));
  if (s.empty()) throw miner::Error(field + ": empty: name a file");
  miner::require_path_without_nul(s, field);
  return s;
}

std::string text_of(py::handle o, const std::string& field) {
  if (!py::isinstance<py::str>(o)) throw miner::Error(field + ": expected a str, got " + type_name(o));
  return py::cast<std::string>(o);
}

template <class T>
const T& object_of(py::handle o, const std::string& field, const char* python_name) {
  if (o.is_none()) throw miner::Error(field + ": expected a miner." + python_name + ", got None");
  try {
    return o.cast<const T&>();
  } catch (const py::cast_error&) {
    throw miner::Error(field + ": expected a miner." + python_name + ", got " +
                       (o.is_none() ? std::string("None") : type_name(o)));
  }
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Eigen::MatrixX3d path_matrix(const std::vector<V3>& path) {
  Eigen::MatrixX3d m(static_cast<Eigen::Index>(path.size()), 3);
  for (std::size_t i = 0; i < path.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = path[i];
  return m;
}

/// A region's probabilities as a (nz, ny, nx) array (x fastest, as the grid stores them).
py::array_t<double> region_grid(const miner::plan::HeuristicRegion& r) {
  const Eigen::Vector3i d = r.dims();
  py::array_t<double> a({d.z(), d.y(), d.x()});
  std::copy(r.probabilities().begin(), r.probabilities().end(), a.mutable_data());
  return a;
}

/// Query of a map: start, goal, radius given, else the map's stored query.
struct Query {
  V3 start, goal;
  double radius;
};
Query resolve(const miner::world::Map& map, py::handle start, py::handle goal, py::handle radius) {
  const auto& q = map.query();
  const std::optional<V3> s = optional_point(start, "start"), g = optional_point(goal, "goal");
  if ((!s || !g) && !q) throw miner::Error("the map has no stored query: give start and goal");
  const double r = radius.is_none() ? (q ? q->robot_radius : 0.0)
                                    : number_in(radius, "radius", 0.0, miner::kMaxRobotRadius, "m");
  return {s ? *s : q->start, g ? *g : q->goal, r};
}

/// A trajectory's k (derivative order): the library refuses k < 0; the bound keeps the int.
int derivative_of(py::handle k) { return static_cast<int>(integer_in(k, "k", 0, 1 << 30)); }

}  // namespace

PYBIND11_MODULE(_miner, m) {
  m.doc() = "MINER-RRT*: learned-heuristic RRT*, MINCO trajectories and a simulated quadrotor";
  static py::exception<miner::Error> error(m, "Error", PyExc_ValueError);
  static py::exception<miner::NoSolution> no_solution(m, "NoSolution", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const miner::NoSolution& e) {
      no_solution(e.what());
    } catch (const miner::Error& e) {
      error(e.what());
    }
  });

  // ------------------------------------------------------------------------- maps
  using miner::world::Map;
  py::class_<Map, std::shared_ptr<Map>>(m, "Map",
      "A bounded 3D workspace of box obstacles and/or voxels (miner-map-v1 JSON, OctoMap .bt/.ot).")
      .def_static("load", [](py::object path) { return std::make_shared<Map>(Map::load(path_of(path, "path"))); },
                  py::arg("path"), "Loads a .json map or an OctoMap .bt/.ot file.")
      .def_static("from_json", [](py::object text) {
            return std::make_shared<Map>(Map::from_json(miner::parse_json(text_of(text, "text"), "<string>"), "<string>"));
          }, py::arg("text"), "A map from its miner-map-v1 JSON text.")
      .def_static("generate", [](py::object preset, py::object seed) {
            return std::make_shared<Map>(
                miner::world::generate_map(miner::world::generator_preset(text_of(preset, "preset")), seed_of(seed)));
          }, py::arg("preset") = "sim", py::arg("seed") = 1,
          "A seeded map of a preset: sim, indoor, cluttered, rooms, forest, multilevel, mixed, scan.")
      .def("save", [](const Map& map, py::object path_arg, py::object drop_query_arg) {
            // The CLI's rules for a map output (REQ-CLI-003, REQ-WORLD-003; ninth campaign P5-P7):
            // .json or .bt exactly, and an OctoMap, which holds voxels only, takes no query unless
            // asked to drop it.
            const std::string path = path_of(path_arg, "path");
            const bool drop_query = flag(drop_query_arg, "drop_query");
            const bool octomap = ends_with(path, ".bt");
            if (!octomap && !ends_with(path, ".json"))
              throw miner::Error("path: " + path + ": a map is written as .json or .bt (exactly, lower case)");
            if (octomap && map.query() && !drop_query)
              throw miner::Error("path: " + path + " is an OctoMap, which holds voxels only, so the map's query (start, "
                                 "goal, robot radius) would be lost; pass drop_query=True, or write .json");
            if (drop_query && !octomap) throw miner::Error("drop_query: only for a .bt path (a .json map keeps its query)");
            map.save(path);
          }, py::arg("path"), py::arg("drop_query") = false,
          "Writes the map as miner-map-v1 JSON (.json) or an OctoMap (.bt, which holds no query: drop_query=True, and no "
          "unknown-space policy: its unknown voxels read as occupied). A generated scan saved as .json writes its voxels "
          "beside it as <stem>.<16 hex digits of their SHA-256>.bt, never replacing a voxel file.")
      .def("to_json", [](const Map& map) { return map.to_json().dump(2); })
      .def_property_readonly("bounds", [](const Map& map) {
            return py::make_tuple(V3(map.bounds().min), V3(map.bounds().max));
          }, "(min, max) corners in m")
      .def_property_readonly("resolution", &Map::resolution)
      .def_property_readonly("obstacles", [](const Map& map) {
            Eigen::MatrixXd boxes(static_cast<Eigen::Index>(map.obstacles().size()), 6);
            for (std::size_t i = 0; i < map.obstacles().size(); ++i)
              boxes.row(static_cast<Eigen::Index>(i)) << map.obstacles()[i].min.transpose(), map.obstacles()[i].max.transpose();
            return boxes;
          }, "(n, 6) array of box obstacles: min x y z, max x y z")
      .def_property_readonly("query", [](const Map& map) -> py::object {
            if (!map.query()) return py::none();
            py::dict d;
            d["start"] = map.query()->start;
            d["goal"] = map.query()->goal;
            d["robot_radius"] = map.query()->robot_radius;
            return std::move(d);
          }, "the stored start, goal and robot radius, or None")
      .def("is_free", [](const Map& map, py::object p, py::object radius) {
            return map.is_free(point_of(p, "p"), number_in(radius, "radius", 0.0, miner::kMaxRobotRadius, "m"));
          }, py::arg("p"), py::arg("radius") = 0.0, "inside the bounds and no obstacle within radius of p")
      .def("segment_free", [](const Map& map, py::object a, py::object b, py::object radius) {
            return map.segment_free(point_of(a, "a"), point_of(b, "b"),
                                    number_in(radius, "radius", 0.0, miner::kMaxRobotRadius, "m"));
          }, py::arg("a"), py::arg("b"), py::arg("radius") = 0.0, "the segment a-b is free at radius")
      .def("clearance", [](const Map& map, py::object p) { return map.clearance(point_of(p, "p")); }, py::arg("p"),
           "distance from p to the nearest obstacle (m)");

  // ---------------------------------------------------------------------- regions
  using miner::plan::HeuristicRegion;
  py::class_<HeuristicRegion>(m, "Region", "A heuristic region H on a grid over the map bounds.")
      .def_static("load", [](py::object path) { return HeuristicRegion::load(path_of(path, "path")); }, py::arg("path"))
      .def("save", [](const HeuristicRegion& r, py::object path_arg) {
            const std::string path = path_of(path_arg, "path");
            if (!ends_with(path, ".json"))
              throw miner::Error("path: " + path + ": a region is written as miner-region-v1 JSON: name it .json");
            r.save(path);
          }, py::arg("path"))
      .def_property_readonly("dims", [](const HeuristicRegion& r) { return Eigen::Vector3i(r.dims()); })
      .def_property_readonly("cell_count", [](const HeuristicRegion& r) { return r.cells().size(); })
      .def_property_readonly("source", &HeuristicRegion::source)
      .def_property_readonly("threshold", &HeuristicRegion::threshold)
      .def_property_readonly("probabilities", &region_grid, "(nz, ny, nx) array of cell probabilities");

  m.def("sgan_region", [](py::object map_arg, py::object start, py::object goal, py::object radius, py::object seed_arg,
                          py::object weights_arg, py::object filter_arg) {
        const Map& map = object_of<Map>(map_arg, "map", "Map");
        const Query q = resolve(map, start, goal, radius);
        const std::uint64_t seed = seed_of(seed_arg);
        const bool filter = flag(filter_arg, "filter");
        const std::string weights = weights_arg.is_none() ? std::string() : path_of(weights_arg, "weights");
        const miner::heuristic::Sgan sgan = miner::heuristic::Sgan::load_or_builtin(weights);
        py::gil_scoped_release unlocked;
        return miner::heuristic::query_region(sgan, map, q.start, q.goal, q.radius, seed, filter).region;
      }, py::arg("map"), py::arg("start") = py::none(), py::arg("goal") = py::none(), py::arg("radius") = py::none(),
      py::arg("seed") = 1, py::arg("weights") = py::none(), py::arg("filter") = true,
      "The sGAN's region for a query (Alg. 1 lines 2-3): the shipped network unless `weights` names a file; "
      "filtered (safe, connected when A* is) unless filter=False.");
  m.def("astar_region", [](py::object map_arg, py::object start, py::object goal, py::object radius, py::object dims_arg,
                           py::object dilation_arg) {
        const Map& map = object_of<Map>(map_arg, "map", "Map");
        const Query q = resolve(map, start, goal, radius);
        // Read once into a list (an iterator is consumed once), then each entry as an integer
        // in [1, 4096] by Python's own rules (a bool is no integer here).
        py::list d;
        try {
          d = py::list(dims_arg);
        } catch (const py::error_already_set&) {
          throw miner::Error("dims: expected 3 integers nx ny nz, got " + type_name(dims_arg));
        }
        if (d.size() != 3) throw miner::Error("dims: expected 3 integers nx ny nz, got " + std::to_string(d.size()));
        Eigen::Vector3i dims;
        for (int k = 0; k < 3; ++k)
          dims[k] = static_cast<int>(integer_in(d[static_cast<std::size_t>(k)], "dims[" + std::to_string(k) + "]", 1, 4096));
        const int dilation = static_cast<int>(integer_in(dilation_arg, "dilation", 0, 4));
        const auto problem = miner::plan::PlanningProblem::make(map, q.start, q.goal, q.radius);
        return miner::plan::astar_dilated_region(problem, miner::plan::astar_reference(problem), dims, dilation);
      }, py::arg("map"), py::arg("start") = py::none(), py::arg("goal") = py::none(), py::arg("radius") = py::none(),
      py::arg("dims") = py::make_tuple(32, 32, 32), py::arg("dilation") = 1,
      "The A*-dilated region (the oracle the network is trained toward).");

  // --------------------------------------------------------------------- planning
  py::class_<miner::plan::PlanResult>(m, "PlanResult")
      .def_readonly("solved", &miner::plan::PlanResult::solved)
      .def_readonly("reason", &miner::plan::PlanResult::reason)
      .def_readonly("cost", &miner::plan::PlanResult::cost)
      .def_readonly("iterations", &miner::plan::PlanResult::iterations)
      .def_readonly("nodes", &miner::plan::PlanResult::nodes)
      .def_readonly("time_ms", &miner::plan::PlanResult::time_ms)
      .def_property_readonly("path", [](const miner::plan::PlanResult& r) { return path_matrix(r.path); }, "(n, 3) waypoints")
      .def_property_readonly("first_iteration", [](const miner::plan::PlanResult& r) -> py::object {
            return r.first ? py::cast(r.first->iteration) : py::none();
          })
      .def_property_readonly("target_iteration", [](const miner::plan::PlanResult& r) -> py::object {
            return r.target ? py::cast(r.target->iteration) : py::none();
          });
  m.def("plan", [](py::object map_arg, py::object start, py::object goal, py::object radius, py::object planner,
                   py::object region_arg, py::object seed, py::object iterations, py::object target_cost,
                   py::object first, py::object safeguard) {
        const Map& map = object_of<Map>(map_arg, "map", "Map");
        const Query q = resolve(map, start, goal, radius);
        const auto problem = miner::plan::PlanningProblem::make(map, q.start, q.goal, q.radius);
        miner::plan::PlannerOptions o;
        o.planner = miner::plan::planner_from_name(text_of(planner, "planner"));
        o.seed = seed_of(seed);
        o.max_iterations = static_cast<std::size_t>(
            integer_in(iterations, "iterations", 1, static_cast<long long>(miner::plan::kMaxIterations)));
        // The CLI's --target-cost range (m): a cost <= 0 is below any path.
        if (!target_cost.is_none()) o.target_cost = number_in(target_cost, "target_cost", 1e-9, 1e9, "m");
        o.stop_at_first = flag(first, "first");
        o.safeguard = flag(safeguard, "safeguard");
        const HeuristicRegion* region = region_arg.is_none() ? nullptr : &object_of<HeuristicRegion>(region_arg, "region", "Region");
        if (o.planner == miner::plan::PlannerKind::kMiner && region == nullptr)
          throw miner::Error("planner \"miner\" needs a region (miner.sgan_region or miner.astar_region)");
        // The region and the safeguard are miner's; the others would ignore them without a word
        // (eleventh campaign P2; the CLI refuses --region for them too).
        if (o.planner != miner::plan::PlannerKind::kMiner) {
          if (region != nullptr)
            throw miner::Error("region: only planner \"miner\" samples a region, not \"" +
                               miner::plan::planner_name(o.planner) + "\"");
          if (!o.safeguard)
            throw miner::Error("safeguard: only planner \"miner\" has the safeguard, not \"" +
                               miner::plan::planner_name(o.planner) + "\"");
        }
        // Ctrl-C reaches a long plan: the planner polls, and the poll raises what Python has
        // pending (KeyboardInterrupt) with the GIL held (eleventh campaign P1).
        o.poll = python_signals;
        miner::plan::PlanResult r;
        {
          py::gil_scoped_release unlocked;
          r = miner::plan::plan(problem, o, region);
        }
        // An unsolved run is miner.NoSolution, as the CLI's exit 3 (ninth campaign P10: it
        // came back with cost 0.0, the best cost there is).
        if (!r.solved) throw miner::NoSolution(r.reason);
        return r;
      }, py::arg("map"), py::arg("start") = py::none(), py::arg("goal") = py::none(), py::arg("radius") = py::none(),
      py::arg("planner") = "miner", py::arg("region") = py::none(), py::arg("seed") = 1, py::arg("iterations") = 20000,
      py::arg("target_cost") = py::none(), py::arg("first") = false, py::arg("safeguard") = true,
      "One run of rrtstar, informed, guided or miner (which samples `region`; `region` and safeguard=False are "
      "refused for the others); the same seed gives the same path. Raises miner.NoSolution when the budget ends "
      "without a path; Ctrl-C raises KeyboardInterrupt within ~1024 iterations.");

  // ------------------------------------------------------------------ trajectories
  using miner::traj::PolynomialTrajectory;
  py::class_<PolynomialTrajectory>(m, "Trajectory", "A piecewise polynomial of order s (MINCO's answer).")
      .def_property_readonly("order", &PolynomialTrajectory::order)
      .def_property_readonly("durations", &PolynomialTrajectory::durations)
      .def_property_readonly("total_duration", &PolynomialTrajectory::total_duration)
      .def_property_readonly("coefficients", &PolynomialTrajectory::coefficients,
                             "(2 s M, 3) stacked monomial coefficients, segment by segment")
      .def_property_readonly("cost", &PolynomialTrajectory::cost, "J = integral of |d^s p / dt^s|^2")
      .def("evaluate", [](const PolynomialTrajectory& t, py::object time, py::object k) {
            return t.evaluate(number(time, "t"), derivative_of(k));
          }, py::arg("t"), py::arg("k") = 0, "the k-th derivative (k >= 0) at a finite time t (clamped to [0, duration])")
      .def("sample", [](const PolynomialTrajectory& t, py::object times_arg, py::object k_arg) {
            const std::vector<double> times = vector_of(times_arg, "times");
            const int k = derivative_of(k_arg);
            Eigen::MatrixX3d out(static_cast<Eigen::Index>(times.size()), 3);
            for (std::size_t i = 0; i < times.size(); ++i) {
              if (!std::isfinite(times[i]))
                throw miner::Error("times[" + std::to_string(i) + "]: must be a finite time in s, got " + miner::short_number(times[i]));
              out.row(static_cast<Eigen::Index>(i)) = t.evaluate(times[i], k);
            }
            return out;
          }, py::arg("times"), py::arg("k") = 0, "(n, 3) k-th derivatives at the given times");
  m.def("minco", [](py::object points_arg, py::object durations_arg, py::object order_arg, py::object v_max_arg,
                    py::object a_max_arg) {
        const Eigen::MatrixX3d p = points_of(points_arg, "points");
        const int order = static_cast<int>(integer_in(order_arg, "order", 3, 4));
        std::vector<double> T;
        if (!durations_arg.is_none()) {
          // Given durations fix the timing: limits beside them would not be applied (as
          // `miner traj solve` refuses them; ninth campaign P14).
          for (const auto& [arg, name] : {std::pair{&v_max_arg, "v_max"}, std::pair{&a_max_arg, "a_max"}})
            if (!arg->is_none())
              throw miner::Error(std::string(name) + ": unused: durations are given (give one of them)");
          T = vector_of(durations_arg, "durations");
        } else {
          // The traj problem file's range (m/s, m/s^2).
          const miner::traj::Limits limits{
              v_max_arg.is_none() ? 2.0 : number_in(v_max_arg, "v_max", 1e-6, 1e6, "m/s"),
              a_max_arg.is_none() ? 1.0 : number_in(a_max_arg, "a_max", 1e-6, 1e6, "m/s^2")};
          T = miner::traj::trapezoidal_allocation(p, limits);
          // A segment too short or too long for doubles has no duration: named by its points,
          // not as a durations[i] the caller never gave (ninth campaign P13).
          for (std::size_t i = 0; i < T.size(); ++i)
            if (!std::isfinite(T[i]) || !(T[i] > 0.0))
              throw miner::Error("points[" + std::to_string(i) + "] and points[" + std::to_string(i + 1) + "]: a segment of " +
                                 miner::short_number((p.row(static_cast<Eigen::Index>(i) + 1) - p.row(static_cast<Eigen::Index>(i))).stableNorm()) +
                                 " m has no trapezoidal duration (" + miner::short_number(T[i]) +
                                 " s at v_max, a_max): too short or too long for double precision");
        }
        return miner::traj::solve_minco(miner::traj::rest_to_rest(order, p, std::move(T)));
      }, py::arg("points"), py::arg("durations") = py::none(), py::arg("order") = 4, py::arg("v_max") = py::none(),
      py::arg("a_max") = py::none(),
      "The minimum-jerk (order 3) or minimum-snap (order 4) trajectory through (n, 3) points, at rest at both "
      "ends; durations given, or from the trapezoidal profile of v_max (default 2 m/s) and a_max (default 1 m/s^2), "
      "which the curve may exceed between waypoints (docs/traj.md). Every answer is checked.");

  // ----------------------------------------------------------------------- flight
  using miner::pipeline::Scenario;
  py::class_<Scenario>(m, "Scenario", "A miner-scenario-v1 flight: map, vehicle, query, sensors, controller.")
      .def_static("load", [](py::object path) { return miner::pipeline::load_scenario(path_of(path, "path")); },
                  py::arg("path"))
      .def_static("default", &miner::pipeline::default_scenario, "the built-in indoor-1 scenario")
      .def_static("from_json", [](py::object text, py::object base_dir_arg) {
            // Relative paths in the text resolve from base_dir, which must be a folder: a lexical
            // "nodir/../maps" picked up files through a folder that is not there (ninth campaign P16).
            const std::string base_dir = path_of(base_dir_arg, "base_dir");
            std::error_code ec;
            if (!std::filesystem::is_directory(base_dir, ec))
              throw miner::Error("base_dir: " + base_dir + " is not a folder");
            return miner::pipeline::scenario_from_json(miner::parse_json(text_of(text, "text"), "<string>"), "<string>",
                                                       base_dir);
          }, py::arg("text"), py::arg("base_dir") = ".")
      .def_readonly("name", &Scenario::name)
      .def_readonly("seed", &Scenario::seed)
      .def_property_readonly("start", [](const Scenario& s) { return V3(s.start); })
      .def_property_readonly("goal", [](const Scenario& s) { return V3(s.goal); })
      .def_property_readonly("map", [](const Scenario& s) { return std::make_shared<Map>(*s.map); });
  using miner::pipeline::ReferencePlan;
  py::class_<ReferencePlan>(m, "Reference", "The trajectory a flight follows and where it came from.")
      .def_readonly("trajectory", &ReferencePlan::trajectory)
      .def_readonly("path", &ReferencePlan::path)
      .def_readonly("source", &ReferencePlan::source)
      .def_readonly("max_speed", &ReferencePlan::max_speed)
      .def_readonly("max_acceleration", &ReferencePlan::max_acceleration);
  m.def("build_reference", [](py::object scenario) {
        const Scenario& s = object_of<Scenario>(scenario, "scenario", "Scenario");
        py::gil_scoped_release unlocked;
        return miner::pipeline::build_reference(s);
      }, py::arg("scenario"), "Plan (MINER RRT* on the sGAN region unless the scenario says otherwise), repair and smooth.");
  py::class_<miner::flight::FlightResult>(m, "Flight", "A closed-loop flight: truth, estimate, commands per controller tick.")
      .def_readonly("position_mse", &miner::flight::FlightResult::position_mse)
      .def_readonly("velocity_mse", &miner::flight::FlightResult::velocity_mse)
      .def_readonly("position_rmse", &miner::flight::FlightResult::position_rmse)
      .def_readonly("max_position_error", &miner::flight::FlightResult::max_position_error)
      .def_readonly("collisions", &miner::flight::FlightResult::collisions)
      .def_readonly("goal_reached", &miner::flight::FlightResult::goal_reached)
      .def_readonly("left_world", &miner::flight::FlightResult::left_world)
      .def_readonly("left_world_time_s", &miner::flight::FlightResult::left_world_time_s)
      .def_readonly("flight_time", &miner::flight::FlightResult::flight_time)
      .def_property_readonly("summary", [](const miner::flight::FlightResult& r) { return r.summary.dump(2); })
      .def_property_readonly("log_columns", [](const miner::flight::FlightResult&) { return miner::flight::flight_log_columns(); })
      .def_property_readonly("log", [](const miner::flight::FlightResult& r) {
            const std::size_t cols = miner::flight::flight_log_columns().size();
            py::array_t<double> a({r.log.size(), cols});
            double* out = a.mutable_data();
            for (const auto& row : r.log) out = std::copy(row.begin(), row.end(), out);
            return a;
          }, "(ticks, columns) array; names in log_columns");
  m.def("fly", [](py::object scenario, py::object reference_arg, py::object log) {
        const Scenario& s = object_of<Scenario>(scenario, "scenario", "Scenario");
        const ReferencePlan& reference = object_of<ReferencePlan>(reference_arg, "reference", "Reference");
        miner::flight::FlyOptions o;
        o.record_log = flag(log, "log");
        o.poll = python_signals;  // Ctrl-C stops a long flight too
        py::gil_scoped_release unlocked;
        return miner::pipeline::fly(s, reference, o);
      }, py::arg("scenario"), py::arg("reference"), py::arg("log") = true,
      "Flies the reference with the scenario's vehicle, sensors, N3, EKF and controller (same seed, same bytes); "
      "the reference must be this scenario's (miner.build_reference(scenario)): one built from a scenario with other "
      "route fields (map, vehicle radius, start, goal, margin, waypoints, trajectory, and planner and seed when it "
      "plans) is refused, naming the field. Ctrl-C raises KeyboardInterrupt "
      "within 4000 N3 ticks (10 s of flight).");
}

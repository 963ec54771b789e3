// Python bindings of MINER (REQ-LIB-002): maps, heuristic regions (sGAN and A* oracle), the
// RRT* family, MINCO, scenarios and closed-loop flights, with numpy arrays in and out.
// `import miner` (src/python/miner/__init__.py) re-exports this module, `_miner`.
//
// Errors: miner::Error (bad input, naming the field) becomes miner.Error, a ValueError;
// miner::NoSolution becomes miner.NoSolution. Long calls (planning, flight) release the GIL.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "miner/core/error.hpp"
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

/// (n, 3) rows of points as an Eigen matrix (numpy in).
Eigen::MatrixX3d rows(const Eigen::Ref<const Eigen::MatrixXd>& a, const char* what) {
  if (a.cols() != 3) throw miner::Error(std::string(what) + ": expected an (n, 3) array, got " + std::to_string(a.rows()) + " x " + std::to_string(a.cols()));
  return a;
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
Query resolve(const miner::world::Map& map, const std::optional<V3>& start, const std::optional<V3>& goal,
              std::optional<double> radius) {
  const auto& q = map.query();
  if ((!start || !goal) && !q) throw miner::Error("the map has no stored query: give start and goal");
  return {start ? *start : q->start, goal ? *goal : q->goal, radius ? *radius : (q ? q->robot_radius : 0.0)};
}

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
  py::class_<miner::world::Map, std::shared_ptr<miner::world::Map>>(m, "Map",
      "A bounded 3D workspace of box obstacles and/or voxels (miner-map-v1 JSON, OctoMap .bt/.ot).")
      .def_static("load", [](const std::string& path) { return std::make_shared<miner::world::Map>(miner::world::Map::load(path)); },
                  py::arg("path"), "Loads a .json map or an OctoMap .bt/.ot file.")
      .def_static("from_json", [](const std::string& text) {
            return std::make_shared<miner::world::Map>(miner::world::Map::from_json(miner::parse_json(text, "<string>"), "<string>"));
          }, py::arg("text"), "A map from its miner-map-v1 JSON text.")
      .def_static("generate", [](const std::string& preset, std::uint64_t seed) {
            return std::make_shared<miner::world::Map>(miner::world::generate_map(miner::world::generator_preset(preset), seed));
          }, py::arg("preset") = "sim", py::arg("seed") = 1,
          "A seeded map of a preset: sim, indoor, cluttered, rooms, forest, multilevel, mixed, scan.")
      .def("save", &miner::world::Map::save, py::arg("path"))
      .def("to_json", [](const miner::world::Map& map) { return map.to_json().dump(2); })
      .def_property_readonly("bounds", [](const miner::world::Map& map) {
            return py::make_tuple(V3(map.bounds().min), V3(map.bounds().max));
          }, "(min, max) corners in m")
      .def_property_readonly("resolution", &miner::world::Map::resolution)
      .def_property_readonly("obstacles", [](const miner::world::Map& map) {
            Eigen::MatrixXd boxes(static_cast<Eigen::Index>(map.obstacles().size()), 6);
            for (std::size_t i = 0; i < map.obstacles().size(); ++i)
              boxes.row(static_cast<Eigen::Index>(i)) << map.obstacles()[i].min.transpose(), map.obstacles()[i].max.transpose();
            return boxes;
          }, "(n, 6) array of box obstacles: min x y z, max x y z")
      .def_property_readonly("query", [](const miner::world::Map& map) -> py::object {
            if (!map.query()) return py::none();
            py::dict d;
            d["start"] = map.query()->start;
            d["goal"] = map.query()->goal;
            d["robot_radius"] = map.query()->robot_radius;
            return std::move(d);
          }, "the stored start, goal and robot radius, or None")
      .def("is_free", &miner::world::Map::is_free, py::arg("p"), py::arg("radius") = 0.0)
      .def("segment_free", &miner::world::Map::segment_free, py::arg("a"), py::arg("b"), py::arg("radius") = 0.0)
      .def("clearance", &miner::world::Map::clearance, py::arg("p"));

  // ---------------------------------------------------------------------- regions
  py::class_<miner::plan::HeuristicRegion>(m, "Region", "A heuristic region H on a grid over the map bounds.")
      .def_static("load", &miner::plan::HeuristicRegion::load, py::arg("path"))
      .def("save", &miner::plan::HeuristicRegion::save, py::arg("path"))
      .def_property_readonly("dims", [](const miner::plan::HeuristicRegion& r) { return Eigen::Vector3i(r.dims()); })
      .def_property_readonly("cell_count", [](const miner::plan::HeuristicRegion& r) { return r.cells().size(); })
      .def_property_readonly("source", &miner::plan::HeuristicRegion::source)
      .def_property_readonly("threshold", &miner::plan::HeuristicRegion::threshold)
      .def_property_readonly("probabilities", &region_grid, "(nz, ny, nx) array of cell probabilities");

  m.def("sgan_region", [](const miner::world::Map& map, std::optional<V3> start, std::optional<V3> goal,
                          std::optional<double> radius, std::uint64_t seed, const std::string& weights, bool filter) {
        const Query q = resolve(map, start, goal, radius);
        const miner::heuristic::Sgan sgan = miner::heuristic::Sgan::load_or_builtin(weights);
        py::gil_scoped_release unlocked;
        return miner::heuristic::query_region(sgan, map, q.start, q.goal, q.radius, seed, filter).region;
      }, py::arg("map"), py::arg("start") = py::none(), py::arg("goal") = py::none(), py::arg("radius") = py::none(),
      py::arg("seed") = 1, py::arg("weights") = "", py::arg("filter") = true,
      "The sGAN's region for a query (Alg. 1 lines 2-3): the shipped network unless `weights` names a file; "
      "filtered (safe, connected when A* is) unless filter=False.");
  m.def("astar_region", [](const miner::world::Map& map, std::optional<V3> start, std::optional<V3> goal,
                           std::optional<double> radius, const Eigen::Vector3i& dims, int dilation) {
        const Query q = resolve(map, start, goal, radius);
        const auto problem = miner::plan::PlanningProblem::make(map, q.start, q.goal, q.radius);
        return miner::plan::astar_dilated_region(problem, miner::plan::astar_reference(problem), dims, dilation);
      }, py::arg("map"), py::arg("start") = py::none(), py::arg("goal") = py::none(), py::arg("radius") = py::none(),
      py::arg("dims") = miner::plan::HeuristicRegion::default_dims(), py::arg("dilation") = 1,
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
  m.def("plan", [](const miner::world::Map& map, std::optional<V3> start, std::optional<V3> goal,
                   std::optional<double> radius, const std::string& planner, const miner::plan::HeuristicRegion* region,
                   std::uint64_t seed, std::size_t iterations, std::optional<double> target_cost, bool first,
                   bool safeguard) {
        const Query q = resolve(map, start, goal, radius);
        const auto problem = miner::plan::PlanningProblem::make(map, q.start, q.goal, q.radius);
        miner::plan::PlannerOptions o;
        o.planner = miner::plan::planner_from_name(planner);
        o.seed = seed;
        o.max_iterations = iterations;
        o.target_cost = target_cost;
        o.stop_at_first = first;
        o.safeguard = safeguard;
        if (o.planner == miner::plan::PlannerKind::kMiner && region == nullptr)
          throw miner::Error("planner \"miner\" needs a region (miner.sgan_region or miner.astar_region)");
        py::gil_scoped_release unlocked;
        return miner::plan::plan(problem, o, region);
      }, py::arg("map"), py::arg("start") = py::none(), py::arg("goal") = py::none(), py::arg("radius") = py::none(),
      py::arg("planner") = "miner", py::arg("region") = nullptr, py::arg("seed") = 1, py::arg("iterations") = 20000,
      py::arg("target_cost") = py::none(), py::arg("first") = false, py::arg("safeguard") = true,
      "One run of rrtstar, informed, guided or miner (which samples `region`); the same seed gives the same path.");

  // ------------------------------------------------------------------ trajectories
  py::class_<miner::traj::PolynomialTrajectory>(m, "Trajectory", "A piecewise polynomial of order s (MINCO's answer).")
      .def_property_readonly("order", &miner::traj::PolynomialTrajectory::order)
      .def_property_readonly("durations", &miner::traj::PolynomialTrajectory::durations)
      .def_property_readonly("total_duration", &miner::traj::PolynomialTrajectory::total_duration)
      .def_property_readonly("coefficients", &miner::traj::PolynomialTrajectory::coefficients,
                             "(2 s M, 3) stacked monomial coefficients, segment by segment")
      .def_property_readonly("cost", &miner::traj::PolynomialTrajectory::cost, "J = integral of |d^s p / dt^s|^2")
      .def("evaluate", &miner::traj::PolynomialTrajectory::evaluate, py::arg("t"), py::arg("k") = 0,
           "the k-th derivative at time t (clamped to the trajectory)")
      .def("sample", [](const miner::traj::PolynomialTrajectory& t, const Eigen::VectorXd& times, int k) {
            Eigen::MatrixX3d out(times.size(), 3);
            for (Eigen::Index i = 0; i < times.size(); ++i) out.row(i) = t.evaluate(times[i], k);
            return out;
          }, py::arg("times"), py::arg("k") = 0, "(n, 3) k-th derivatives at the given times");
  m.def("minco", [](const Eigen::Ref<const Eigen::MatrixXd>& points, std::optional<std::vector<double>> durations,
                    int order, double v_max, double a_max) {
        const Eigen::MatrixX3d p = rows(points, "points");
        std::vector<double> T = durations ? *durations : miner::traj::trapezoidal_allocation(p, miner::traj::Limits{v_max, a_max});
        return miner::traj::solve_minco(miner::traj::rest_to_rest(order, p, std::move(T)));
      }, py::arg("points"), py::arg("durations") = py::none(), py::arg("order") = 4, py::arg("v_max") = 2.0,
      py::arg("a_max") = 1.0,
      "The minimum-jerk (order 3) or minimum-snap (order 4) trajectory through (n, 3) points, at rest at both "
      "ends; durations given, or from the trapezoidal profile of v_max and a_max. Every answer is checked.");

  // ----------------------------------------------------------------------- flight
  py::class_<miner::pipeline::Scenario>(m, "Scenario", "A miner-scenario-v1 flight: map, vehicle, query, sensors, controller.")
      .def_static("load", &miner::pipeline::load_scenario, py::arg("path"))
      .def_static("default", &miner::pipeline::default_scenario, "the built-in indoor-1 scenario")
      .def_static("from_json", [](const std::string& text, const std::string& base_dir) {
            return miner::pipeline::scenario_from_json(miner::parse_json(text, "<string>"), "<string>", base_dir);
          }, py::arg("text"), py::arg("base_dir") = ".")
      .def_readonly("name", &miner::pipeline::Scenario::name)
      .def_readonly("seed", &miner::pipeline::Scenario::seed)
      .def_property_readonly("start", [](const miner::pipeline::Scenario& s) { return V3(s.start); })
      .def_property_readonly("goal", [](const miner::pipeline::Scenario& s) { return V3(s.goal); })
      .def_property_readonly("map", [](const miner::pipeline::Scenario& s) { return std::make_shared<miner::world::Map>(*s.map); });
  py::class_<miner::pipeline::ReferencePlan>(m, "Reference", "The trajectory a flight follows and where it came from.")
      .def_readonly("trajectory", &miner::pipeline::ReferencePlan::trajectory)
      .def_readonly("path", &miner::pipeline::ReferencePlan::path)
      .def_readonly("source", &miner::pipeline::ReferencePlan::source)
      .def_readonly("max_speed", &miner::pipeline::ReferencePlan::max_speed)
      .def_readonly("max_acceleration", &miner::pipeline::ReferencePlan::max_acceleration);
  m.def("build_reference", [](const miner::pipeline::Scenario& s) {
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
  m.def("fly", [](const miner::pipeline::Scenario& s, const miner::pipeline::ReferencePlan& reference, bool log) {
        miner::flight::FlyOptions o;
        o.record_log = log;
        py::gil_scoped_release unlocked;
        return miner::pipeline::fly(s, reference, o);
      }, py::arg("scenario"), py::arg("reference"), py::arg("log") = true,
      "Flies the reference with the scenario's vehicle, sensors, N3, EKF and controller (same seed, same bytes).");
}

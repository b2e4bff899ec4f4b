// metrics.json: planned and simulated figures under their own names, order.refine null when
// there is none, and a units block that names the unit of every number; trajectory.csv's
// header with its units.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "report/metrics_json.hpp"
#include "report/trajectory_csv.hpp"

namespace depotwin {
namespace {

using Json = nlohmann::ordered_json;

// a plan's report: planned figures only
MetricsReport planned_report() {
  MetricsReport r;
  r.scenario = "fixture";
  r.machine = "xy_stage";
  r.planner = "lspb_mtt";
  r.time = {19.0, 11.0, 8.0};
  r.planned_velocity_error = {0.6, 0.05, 0.1, 0.02};
  r.planned_velocity_error_steady = {0.3, 0.01, 0.02, 0.01, 7.6};
  r.planned_path_error = {0.04, 0.01};
  r.speed_ramps = {{1.0, 1.1}, {2.0, 2.3}};
  OrderStats order;
  order.cost_s = 19.0;
  r.order = order;
  return r;
}

// a run's report: every section, with a hinge and a slide, two layers and the arm
MetricsReport simulated_report() {
  MetricsReport r = planned_report();
  r.velocity_error = VelocityErrorStats{0.61, 0.05, 0.1, 0.02};
  r.velocity_error_steady = VelocityErrorStats{0.31, 0.01, 0.02, 0.01, 7.6};
  r.path_error = PathErrorStats{0.05, 0.01};
  r.thickness = ThicknessSummary{1.2, 0.5, 0.08, 0.1, 1.9};
  r.waste = WasteStats{0.45, 0.4, 0.05, 8.0};
  r.material = MaterialStats{10.0, 5.5, 0.5, 4.0};
  ActuatorStats a;
  a.joint_names = {"x", "j2"};
  a.revolute = {false, true};
  a.peak_vel = a.peak_acc = a.peak_force = a.limit_vel = a.limit_acc = a.limit_force = {1.0, 2.0};
  a.plan_peak_acc = a.peak_acc_over_plan = {1.0, 2.0};
  r.actuators = a;
  r.order->lower_bound_s = 18.0;
  r.sim = SimStats{19000, 0.001, 0.1, 190.0, 0.0};
  ArmStats arm;
  arm.best_fixed.feasible = false;  // its mean_cost is null
  r.arm = arm;
  for (int k = 0; k < 2; ++k) {
    LayerReport layer;
    layer.layer = k;
    layer.velocity_error = VelocityErrorStats{};
    layer.velocity_error_steady = VelocityErrorStats{0, 0, 0, 0, 1.0};
    layer.planned_velocity_error_steady = VelocityErrorStats{0, 0, 0, 0, 1.0};
    layer.path_error = PathErrorStats{};
    layer.thickness = ThicknessSummary{};
    layer.waste = WasteStats{};
    layer.material = MaterialStats{};
    r.layers.push_back(layer);
  }
  return r;
}

// Every number of `values` has a unit (a non-empty string) at the same place in `units`: an
// array of numbers one unit per element, an array of objects one units object for all.
void expect_units_cover(const Json& values, const Json& units, const std::string& where,
                        int& numbers) {
  if (values.is_number()) {
    ++numbers;
    ASSERT_TRUE(units.is_string()) << where << " has no unit";
    EXPECT_FALSE(units.get<std::string>().empty()) << where;
  } else if (values.is_object()) {
    for (const auto& [key, value] : values.items()) {
      if (!value.is_number() && !value.is_object() && !value.is_array()) continue;
      if (value.is_array() && (value.empty() || value.front().is_string())) continue;  // names
      ASSERT_TRUE(units.is_object() && units.contains(key)) << where + "." + key << " has no unit";
      expect_units_cover(value, units[key], where + "." + key, numbers);
    }
  } else if (values.is_array()) {
    for (size_t i = 0; i < values.size(); ++i) {
      const Json& element = values[i];
      if (element.is_string()) continue;  // names
      if (element.is_object()) {
        expect_units_cover(element, units, where + "[" + std::to_string(i) + "]", numbers);
      } else {
        ASSERT_TRUE(units.is_array() && units.size() == values.size()) << where;
        expect_units_cover(element, units[i], where + "[" + std::to_string(i) + "]", numbers);
      }
    }
  }
}

TEST(MetricsJson, UnitsBlockCoversEveryNumber) {
  for (const MetricsReport& report : {planned_report(), simulated_report()}) {
    const Json j = Json::parse(metrics_json_text(report));
    ASSERT_TRUE(j.contains("units"));
    Json values = j;
    values.erase("units");
    int numbers = 0;
    expect_units_cover(values, j["units"], "metrics", numbers);
    EXPECT_EQ(numbers, report.sim ? 174 : 17);  // every number counted once
  }
}

TEST(MetricsJson, UnitsNameTheQuantities) {
  const Json u = Json::parse(metrics_json_text(simulated_report()))["units"];
  EXPECT_EQ(u["time_s"]["total"], "s");
  EXPECT_EQ(u["velocity_error"]["max_rel"], "fraction");
  EXPECT_EQ(u["path_error_mm"]["max"], "mm");
  EXPECT_EQ(u["thickness"]["mean_um"], "µm");
  EXPECT_EQ(u["material_mm3"]["emitted"], "mm^3");
  EXPECT_EQ(u["actuators"]["peak_vel"], (Json{"mm/s", "deg/s"}));
  EXPECT_EQ(u["actuators"]["peak_acc"], (Json{"mm/s^2", "deg/s^2"}));
  EXPECT_EQ(u["actuators"]["peak_force"], (Json{"N", "N m"}));
  EXPECT_EQ(u["layers"]["thickness"]["mean_um"], "µm");
  EXPECT_EQ(u["arm"]["min_joint_margin_deg"], "deg");
}

// plan: planned_* only; run: the contract's keys (simulated) beside the planned ones
TEST(MetricsJson, PlannedAndSimulatedFiguresHaveTheirOwnNames) {
  const Json plan = Json::parse(metrics_json_text(planned_report()));
  for (const char* key : {"velocity_error", "velocity_error_steady", "path_error_mm"})
    EXPECT_FALSE(plan.contains(key)) << key;
  EXPECT_EQ(plan["planned_path_error_mm"]["max"], 0.04);
  EXPECT_EQ(plan["planned_velocity_error"]["max_rel"], 0.6);
  EXPECT_EQ(plan["planned_velocity_error_steady"]["max_rel"], 0.3);
  EXPECT_EQ(plan["speed_ramps"]["count"], 2);
  EXPECT_NEAR(plan["speed_ramps"]["time_s"].get<double>(), 0.4, 1e-12);

  const Json run = Json::parse(metrics_json_text(simulated_report()));
  EXPECT_EQ(run["velocity_error"]["max_rel"], 0.61);
  EXPECT_EQ(run["velocity_error_steady"]["max_rel"], 0.31);
  EXPECT_EQ(run["path_error_mm"]["max"], 0.05);
  EXPECT_EQ(run["planned_path_error_mm"]["max"], 0.04);
  EXPECT_EQ(run["planned_velocity_error"]["max_rel"], 0.6);
  // the contract's keys, in the contract's shape
  for (const char* key : {"max_rel", "rms_rel", "p95_rel", "frac_len_over_1pct"})
    EXPECT_TRUE(run["velocity_error_steady"].contains(key)) << key;
  EXPECT_TRUE(run["layers"][0].contains("planned_path_error_mm"));
  EXPECT_TRUE(run["layers"][0].contains("velocity_error_steady"));
}

// a run that is all ramps has no steady figures: the keys are there, null (n/a), not 0
TEST(MetricsJson, SteadyErrorsOverNoTimeAreNull) {
  MetricsReport report = simulated_report();
  report.velocity_error_steady = VelocityErrorStats{};
  report.planned_velocity_error_steady = VelocityErrorStats{};
  const Json j = Json::parse(metrics_json_text(report));
  for (const char* section : {"velocity_error_steady", "planned_velocity_error_steady"})
    for (const char* key : {"max_rel", "rms_rel", "p95_rel", "frac_len_over_1pct"}) {
      ASSERT_TRUE(j[section].contains(key)) << section << "." << key;
      EXPECT_TRUE(j[section][key].is_null()) << section << "." << key;
      EXPECT_EQ(j["units"][section][key], "fraction");
    }
  EXPECT_EQ(j["velocity_error"]["max_rel"], 0.61);  // the whole-length figures stay
}

// the contract of docs/ARCHITECTURE.md ("metrics.json"): every key under its name, holding the
// report's value (the fixture's own numbers, not the writer's), with its unit
TEST(MetricsJson, ContractKeysHoldTheReportsValues) {
  const Json j = Json::parse(metrics_json_text(simulated_report()));
  EXPECT_EQ(j["scenario"], "fixture");
  EXPECT_EQ(j["machine"], "xy_stage");
  EXPECT_EQ(j["planner"], "lspb_mtt");
  EXPECT_EQ(j["sequencer"], "as_given");
  const auto expect_section = [&](const char* section, const std::vector<const char*>& keys,
                                  const std::vector<double>& values, const char* unit) {
    ASSERT_TRUE(j.contains(section)) << section;
    for (size_t k = 0; k < keys.size(); ++k) {
      ASSERT_TRUE(j[section].contains(keys[k])) << section << "." << keys[k];
      EXPECT_DOUBLE_EQ(j[section][keys[k]].get<double>(), values[k]) << section << "." << keys[k];
      if (unit) {
        EXPECT_EQ(j["units"][section][keys[k]], unit) << section << "." << keys[k];
      }
    }
  };
  expect_section("time_s", {"total", "print", "transition"}, {19.0, 11.0, 8.0}, "s");
  const std::vector<const char*> velocity_keys = {"max_rel", "rms_rel", "p95_rel",
                                                  "frac_len_over_1pct"};
  expect_section("velocity_error", velocity_keys, {0.61, 0.05, 0.1, 0.02}, "fraction");
  expect_section("planned_velocity_error", velocity_keys, {0.6, 0.05, 0.1, 0.02}, "fraction");
  expect_section("path_error_mm", {"max", "rms"}, {0.05, 0.01}, "mm");
  expect_section("thickness", {"mean_um", "cv", "line_cv", "min_rel", "max_rel"},
                 {1.2, 0.5, 0.08, 0.1, 1.9}, nullptr);
  EXPECT_EQ(j["units"]["thickness"]["mean_um"], "µm");
  expect_section("waste", {"fraction", "shutter_captured", "overspray"}, {0.45, 0.4, 0.05},
                 "fraction");
  expect_section("waste", {"closed_time_s"}, {8.0}, "s");
  expect_section("material_mm3", {"emitted", "on_target", "overspray", "captured"},
                 {10.0, 5.5, 0.5, 4.0}, "mm^3");
  // emitted = the sum of the other three, as the contract says of the fixture's volumes
  const Json& material = j["material_mm3"];
  EXPECT_DOUBLE_EQ(material["emitted"].get<double>(), material["on_target"].get<double>() +
                                                          material["overspray"].get<double>() +
                                                          material["captured"].get<double>());
  for (const char* key : {"peak_vel", "peak_acc", "peak_force"}) {
    ASSERT_TRUE(j["actuators"].contains(key)) << key;
    EXPECT_EQ(j["actuators"][key], (Json{1.0, 2.0})) << key;
  }
  EXPECT_EQ(j["actuators"]["limit_violations"], 0);
  EXPECT_EQ(j["order"]["method"], "as_given");
  EXPECT_TRUE(j["order"]["refine"].is_null());
  EXPECT_EQ(j["order"]["cost_model"], "machine");
  EXPECT_DOUBLE_EQ(j["order"]["cost_s"].get<double>(), 19.0);
  EXPECT_DOUBLE_EQ(j["order"]["lower_bound_s"].get<double>(), 18.0);
  EXPECT_TRUE(j["warnings"].is_array());
  EXPECT_EQ(j["sim"]["steps"], 19000);
  EXPECT_DOUBLE_EQ(j["sim"]["timestep_s"].get<double>(), 0.001);
  EXPECT_DOUBLE_EQ(j["sim"]["wall_s"].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(j["sim"]["realtime_factor"].get<double>(), 190.0);
  EXPECT_EQ(j["units"]["sim"]["timestep_s"], "s");
  // a warning the run gave is written as given
  MetricsReport warned = simulated_report();
  warned.warnings = {"path 3: lengthened"};
  EXPECT_EQ(Json::parse(metrics_json_text(warned))["warnings"], (Json{"path 3: lengthened"}));
}

TEST(MetricsJson, OrderRefineIsNullWithoutOne) {
  MetricsReport r = planned_report();
  EXPECT_TRUE(Json::parse(metrics_json_text(r))["order"]["refine"].is_null());
  r.order->refine = "three_opt";
  EXPECT_EQ(Json::parse(metrics_json_text(r))["order"]["refine"], "three_opt");
}

TEST(TrajectoryCsv, HeaderNamesEveryUnit) {
  MotionSamples s;
  s.push_back(0.0, Vec3(1, 2, 0), Vec3(3, 4, 0), true, 0, 5.0);
  s.push_back(0.001, Vec3(1, 2, 0), Vec3(0, 0, 0), false, -1, 0.0);
  const std::string planned = planned_trajectory_csv(s);
  EXPECT_EQ(planned.substr(0, planned.find('\n')),
            "t_s,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,speed_mm_s,depositing,path,"
            "desired_speed_mm_s");
  EXPECT_NE(planned.find("\n0.001000,1,2,0,0,0,0,0,0,-1,0\n"), std::string::npos) << planned;
  const std::string both = planned_and_simulated_csv(s, s);
  EXPECT_EQ(both.substr(0, both.find('\n')),
            "t_s,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,speed_mm_s,depositing,path,"
            "desired_speed_mm_s,sim_x_mm,sim_y_mm,sim_z_mm,sim_vx_mm_s,sim_vy_mm_s,sim_vz_mm_s,"
            "sim_speed_mm_s");
  EXPECT_NE(both.find("\n0.000000,1,2,0,3,4,0,5,1,0,5,1,2,0,3,4,0,5\n"), std::string::npos) << both;
}

}  // namespace
}  // namespace depotwin

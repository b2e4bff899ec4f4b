// A job's deposit layer by layer: one Process per layer (the steps of a layer's paths go to
// that layer's process), the layers stacked into one deposit, the material summed over them.
// A planar job has one layer, and its deposit is that layer's field as it is.
//
// On a curved part (conformal work) the field holds vertical thickness, the volume per unit of
// (x, y) area: material lands on the part's surface, whose area over a cell is the cell's area
// / n_z (n_z the z component of the surface's unit normal). The thickness along the surface
// normal is therefore the vertical thickness times n_z, exactly, on any height-field surface:
// normal_field() holds it when a normal_z function is given. Volumes (material balance) come
// from the vertical field; thickness statistics, maps and the scene from the normal one.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "deposition/process.hpp"
#include "deposition/thickness_field.hpp"

namespace depotwin {

class LayeredDeposit {
 public:
  using NormalZ = std::function<double(double x_mm, double y_mm)>;

  // layers >= 1; cell_mm as in Process; normal_z: the surface normal's z component under a
  // point (null: a flat substrate, n_z = 1 everywhere)
  LayeredDeposit(const DepositionSettings& settings, double cell_mm, int layers,
                 NormalZ normal_z = nullptr);

  int layer_count() const { return static_cast<int>(layers_.size()); }
  Process& layer(int k) { return *layers_.at(static_cast<size_t>(k)); }
  const Process& layer(int k) const { return *layers_.at(static_cast<size_t>(k)); }
  // one simulation step into layer k's process (k clamped to the layers); the steps come in
  // time order, and the nozzle's lagging flow follows them from layer to layer
  void advance(const DepositionStep& step, int k);

  // after the last step: every layer's batched steps put down, the layers stacked and, on a
  // curved part, turned into normal thickness. Before finish() the fields below are empty.
  void finish();
  // every layer stacked: vertical thickness (volume per (x, y) area)
  const ThicknessField& field() const;
  // thickness along the surface normal (the same as field() on a flat substrate)
  const ThicknessField& normal_field() const;
  // one layer's normal thickness
  const ThicknessField& layer_normal_field(int k) const;
  // the material of every layer, summed
  MaterialAccount account() const;

  const DepositionSettings& settings() const { return layers_.front()->settings(); }
  double line_width_mm() const { return layers_.front()->line_width_mm(); }
  double footprint_sigma_mm() const { return layers_.front()->footprint_sigma_mm(); }
  bool curved() const { return static_cast<bool>(normal_z_); }
  // the process of layer 0: its settings, flow and lag (e.g. the extruder's ooze at the end)
  Process& front() { return *layers_.front(); }
  const Process& front() const { return *layers_.front(); }

 private:
  std::vector<std::unique_ptr<Process>> layers_;
  NormalZ normal_z_;
  size_t current_layer_ = 0;  // the layer of the last step (whose process holds the flow)
  bool finished_ = false;
  ThicknessField stacked_;                    // several layers: their sum
  std::unique_ptr<ThicknessField> normal_;    // curved: stacked times n_z
  std::vector<ThicknessField> layer_normal_;  // curved, several layers: each times n_z
};

}  // namespace depotwin

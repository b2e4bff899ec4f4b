#include "deposition/layered_deposit.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace depotwin {

LayeredDeposit::LayeredDeposit(const DepositionSettings& settings, double cell_mm, int layers,
                               NormalZ normal_z)
    : normal_z_(std::move(normal_z)), stacked_(1.0) {
  if (layers < 1) throw InternalError("a deposit needs at least one layer");
  for (int k = 0; k < layers; ++k) layers_.push_back(make_process(settings, cell_mm));
  stacked_ = ThicknessField(layers_.front()->field().cell_mm());
}

void LayeredDeposit::advance(const DepositionStep& step, int k) {
  const auto layer = static_cast<size_t>(std::clamp(k, 0, layer_count() - 1));
  // one nozzle: the flow still leaving it when the steps move on to another layer (the lag's
  // tail over a layer change) goes on into that layer, never dropped
  if (layer != current_layer_) {
    layers_[layer]->take_nozzle_flow_from(*layers_[current_layer_]);
    current_layer_ = layer;
  }
  layers_[layer]->advance(step);
}

void LayeredDeposit::finish() {
  for (auto& process : layers_) process->flush();
  // several layers: their sum
  if (layers_.size() > 1) {
    stacked_.clear();
    for (const auto& process : layers_) stacked_.add(process->field());
  }
  finished_ = true;
  // a curved part: thickness along the normal, per layer and stacked
  layer_normal_.clear();
  normal_.reset();
  if (normal_z_) {
    const double cell_mm = stacked_.cell_mm();
    normal_ = std::make_unique<ThicknessField>(cell_mm);
    normal_->add(field());
    normal_->scale_cells(normal_z_);
    if (layers_.size() > 1) {
      for (const auto& process : layers_) {
        layer_normal_.emplace_back(cell_mm);
        layer_normal_.back().add(process->field());
        layer_normal_.back().scale_cells(normal_z_);
      }
    }
  }
}

const ThicknessField& LayeredDeposit::field() const {
  if (!finished_) throw InternalError("LayeredDeposit::field() before finish()");
  return layers_.size() > 1 ? stacked_ : layers_.front()->field();
}

const ThicknessField& LayeredDeposit::normal_field() const {
  return normal_ ? *normal_ : field();
}

const ThicknessField& LayeredDeposit::layer_normal_field(int k) const {
  if (!finished_) throw InternalError("LayeredDeposit::layer_normal_field() before finish()");
  if (!layer_normal_.empty()) return layer_normal_.at(static_cast<size_t>(k));
  if (layers_.size() == 1 && normal_) return *normal_;
  return layer(k).field();
}

MaterialAccount LayeredDeposit::account() const {
  MaterialAccount total;
  for (const auto& process : layers_) {
    const MaterialAccount& a = process->account();
    total.emitted_mm3 += a.emitted_mm3;
    total.captured_mm3 += a.captured_mm3;
    total.landed_mm3 += a.landed_mm3;
    total.closed_time_s += a.closed_time_s;
  }
  return total;
}

}  // namespace depotwin

// The network's device view, shared with the renderers (render/): the flat
// MlpHD of the SKYBAKE_HD forward pass (mlp_hd.h) built from a NeuralSky.
#pragma once

#include "neural/mlp_hd.h"
#include "skybake/neural.h"

namespace skybake::neural {

MlpHD make_mlp_hd(const NeuralSky& net);

} // namespace skybake::neural

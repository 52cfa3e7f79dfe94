// Stack outputs of the writer registry (layer_writer.h): writers that need every layer.
#pragma once

#include <memory>

#include "trivox/output/layer_writer.h"

namespace trivox::detail {

// "preview": contact sheet and three orthogonal cuts (preview_writer.cpp).
std::unique_ptr<LayerWriter> make_preview_writer(const OutputContext& context);

}  // namespace trivox::detail

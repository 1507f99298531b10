// The pair processors the pipeline runs: what turns two frames into angular rates.
#pragma once

#include <map>

#include "inertialnet/models/parameters.hpp"
#include "inertialnet/models/weights.hpp"
#include "inertialnet/pipeline.hpp"

namespace inertialnet {

struct LearnedProcessorOptions {
  ModelKind flow_model = ModelKind::FlowNet2;
  bool keep_flow = false;  // download the dense flow into PairResult::flow (--save-flow)
};

// FlowNet2 (or a lighter family member) → InertialNet head, rates named "inertialnet". Each lane
// gets its own queue and network instances over its device's weights (`weights` holds one set
// per device, loaded beforehand; they must outlive the pipeline).
ProcessorFactory learned_processor(const std::map<const Device*, const WeightSet*>& weights,
                                   const LearnedProcessorOptions& options);

}  // namespace inertialnet

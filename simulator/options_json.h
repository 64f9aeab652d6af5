// Every field of SimulationOptions as JSON (numbers as numbers), for
// truth/meta.json. Internal to the simulator library.
#ifndef ZEBRAGEO_SIMULATOR_OPTIONS_JSON_H_
#define ZEBRAGEO_SIMULATOR_OPTIONS_JSON_H_

#include <nlohmann/json.hpp>

#include "simulator/simulator.h"

namespace zebrageo {

nlohmann::json OptionsToJson(const SimulationOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SIMULATOR_OPTIONS_JSON_H_

// CROSSRT_DEVICE_FEATURES: the optional device features a context may use. "-name" hides a
// feature the device offers, so the generated classes take their software fallback as they would
// on a GPU without it; "+name" requires one, so a test of a hardware path fails (rather than
// quietly testing the fallback) on a device without it.
#include "Internal.h"

#include <sstream>

namespace crossrt {

namespace {
const char* const kNames[] = {"ray_query", "ray_tracing_pipeline", "texture_arrays", "float_atomics"};
static_assert(sizeof(kNames) / sizeof(kNames[0]) == size_t(DeviceFeature::Count), "one name per feature");
}  // namespace

const char* DeviceFeatureName(DeviceFeature f) { return kNames[size_t(f)]; }

DeviceFeatureMask ParseDeviceFeatures(const std::string& text) {
  DeviceFeatureMask mask;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) continue;
    const char sign = item[0];
    const std::string name = item.substr(1);
    size_t f = 0;
    while (f < size_t(DeviceFeature::Count) && name != kNames[f]) ++f;
    if ((sign != '-' && sign != '+') || f == size_t(DeviceFeature::Count)) {
      std::string known;
      for (const char* k : kNames) known += std::string(known.empty() ? "" : ", ") + k;
      throw Error("CROSSRT_DEVICE_FEATURES: '" + item + "' is not -name (hide) or +name (require) with a name among " +
                  known);
    }
    (sign == '-' ? mask.hidden : mask.required)[f] = true;
    (sign == '-' ? mask.required : mask.hidden)[f] = false;  // the last word on a feature wins
  }
  return mask;
}

}  // namespace crossrt

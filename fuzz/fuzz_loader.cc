// libFuzzer target: the scenario loader must answer any bytes with a Model or a ScenarioError,
// never a crash, a hang or another exception.
#include "mechbench/errors.h"
#include "mechbench/loader.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    mechbench::LoadScenarioFromString(text, "fuzz.yaml");
  } catch (const mechbench::ScenarioError&) {
  }
  return 0;
}

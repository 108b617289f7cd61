// The names of generated members that the engine writes into host code (GeneratedNames.h) are the
// names the Vulkan class template declares: a rename on one side only would generate code that
// does not compile.
#include "EngineSupport.h"
#include "generate/GeneratedNames.h"

#include <regex>

using namespace crossrt::engine;

TEST_CASE("Generated names: the Vulkan class template declares every member the engine writes", "[engine][names]")
{
  std::ifstream in(CROSSRT_SOURCE_DIR "/templates/vulkan/class.h.mustache");
  REQUIRE(in);
  const std::string header((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string& name : {generated::kVectorCopies, generated::kTemporaries, generated::kThreadState, generated::kScanner, generated::kSorter,
                                  generated::kVirtualObjects, generated::kImages, generated::kTextures, generated::kPartials, generated::kPipelines,
                                  generated::kClassData, generated::kPipelineConstants})
  {
    INFO(name);
    // A member declaration: `Type name;` or the closing `} name;` of a member struct.
    CHECK(std::regex_search(header, std::regex("[\\w>}] " + name + ";")));
  }
  // The per-control-function buffers: `} crt_inOut_<control>;`.
  CHECK(header.find("} " + generated::kInOutPrefix + "{{name}};") != std::string::npos);
}

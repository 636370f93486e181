// libFuzzer target for farm plan files. Any input may be rejected with deformkit::Error; anything else is a
// bug. A plan that parses must survive formatFarmPlan and a second parse unchanged.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "deformkit/error.h"
#include "deformkit/scene/farm_plan.h"

namespace {

bool identical(const deformkit::scene::FarmPlan& a, const deformkit::scene::FarmPlan& b) {
    if (a.scene != b.scene || a.outDir != b.outDir || a.chunk != b.chunk || a.warmUp != b.warmUp)
        return false;
    if (a.tasks.size() != b.tasks.size()) return false;
    for (size_t i = 0; i < a.tasks.size(); ++i) {
        const auto& x = a.tasks[i];
        const auto& y = b.tasks[i];
        if (x.firstFrame != y.firstFrame || x.lastFrame != y.lastFrame || x.tiles != y.tiles ||
            x.outputs != y.outputs)
            return false;
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    deformkit::scene::FarmPlan plan;
    try {
        plan = deformkit::scene::parseFarmPlan(text, "plan.json");
    } catch (const deformkit::Error&) {
        return 0;
    }
    const deformkit::scene::FarmPlan again =
        deformkit::scene::parseFarmPlan(deformkit::scene::formatFarmPlan(plan), "plan.json");
    if (!identical(plan, again)) std::abort();
    return 0;
}

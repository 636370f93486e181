#pragma once

// Farm plans edited by hand, as a user might: each edit replaces one piece of a good plan's JSON, and running
// the edited plan must fail with an InvalidInput error that names the file and the element.

#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <span>
#include <string>

#include "deformkit/error.h"
#include "farm_command.h"
#include "test_support.h"

namespace deformkit::test {

struct PlanEdit {
    const char* from;     // text of the good plan
    const char* to;       // what it becomes
    const char* message;  // what the error says after the plan file's name
};

// Writes each edit of `good` to `planFile`, runs it and checks the error.
inline void checkPlanEdits(const std::string& good, const std::filesystem::path& planFile,
                           std::span<const PlanEdit> edits) {
    for (const PlanEdit& edit : edits) {
        std::string text = good;
        const size_t at = text.find(edit.from);
        REQUIRE(at != std::string::npos);
        text.replace(at, std::strlen(edit.from), edit.to);
        writeText(planFile, text);
        CAPTURE(edit.to);
        const std::string what = errorOf<InvalidInput>([&] { (void)harness::farmRunCommand({planFile, 1}); });
        CHECK_THAT(what, Catch::Contains(planFile.string() + edit.message));
    }
}

}  // namespace deformkit::test

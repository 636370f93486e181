#include "progress_bar.h"

#include <algorithm>
#include <sstream>
#include <string>

namespace deformkit::harness {
namespace {

std::string clockText(double seconds) {
    const auto total = static_cast<int64_t>(seconds + 0.5);
    const int64_t h = total / 3600, m = (total / 60) % 60, s = total % 60;
    std::ostringstream out;
    if (h > 0) out << h << ":" << (m < 10 ? "0" : "");
    out << m << ":" << (s < 10 ? "0" : "") << s;
    return out.str();
}

}  // namespace

void ProgressBar::start(std::string_view name, int64_t) {
    name_ = name;
    start_ = std::chrono::steady_clock::now();
}

void ProgressBar::end() {
    if (drawn_) out_ << "\n" << std::flush;
    drawn_ = false;
}

bool ProgressBar::wasInterrupted(int64_t done, int64_t total, std::string_view unit) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int64_t remaining = std::max<int64_t>(total - done, 0);
    const double eta = done > 0 ? elapsed / static_cast<double>(done) * static_cast<double>(remaining) : 0.0;
    constexpr int64_t kWidth = 24;
    const int64_t filled = total > 0 ? std::min(kWidth, kWidth * done / total) : kWidth;
    out_ << "\r" << name_ << " [" << std::string(static_cast<size_t>(filled), '#')
         << std::string(static_cast<size_t>(kWidth - filled), '-') << "] " << done << "/" << total << "  "
         << unit << "  elapsed " << clockText(elapsed) << "  ETA " << clockText(eta) << "   " << std::flush;
    drawn_ = true;
    return false;
}

}  // namespace deformkit::harness

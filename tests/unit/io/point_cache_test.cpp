#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/animated_positions.h"
#include "deformkit/io/obj.h"
#include "deformkit/io/point_cache.h"
#include "point_cache_support.h"
#include "test_support.h"

using namespace deformkit;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// `frames` frames of `vertices` random positions (fixed seed), some large, some tiny, some negative.
std::vector<std::vector<glm::vec3>> randomFrames(int frames, int vertices, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
    std::uniform_int_distribution<int> exponent(-20, 20);
    std::vector<std::vector<glm::vec3>> out(static_cast<size_t>(frames));
    for (auto& frame : out)
        for (int v = 0; v < vertices; ++v)
            frame.emplace_back(std::ldexp(mantissa(rng), exponent(rng)),
                               std::ldexp(mantissa(rng), exponent(rng)),
                               std::ldexp(mantissa(rng), exponent(rng)));
    return out;
}

std::vector<glm::vec3> read(io::PointCache& cache, int frame) {
    std::vector<glm::vec3> points;
    cache.read(frame, points);
    return points;
}

}  // namespace

TEST_CASE("point cache: PC2 and MDD written by hand read back bit for bit, frames from start and sampling",
          "[io][point_cache]") {
    const test::TempDir dir;
    const auto frames = randomFrames(5, 7, 11);

    SECTION("PC2, start 10, one frame per sample") {
        test::writeText(dir / "a.pc2", test::pc2Bytes(10.0f, 1.0f, frames));
        io::PointCache cache(dir / "a.pc2");
        CHECK(cache.format() == io::PointCacheFormat::Pc2);
        CHECK(cache.vertexCount() == 7);
        CHECK(cache.sampleCount() == 5);
        CHECK(cache.frames() == std::vector<int>{10, 11, 12, 13, 14});
        // Random access, in any order.
        for (int frame : {13, 10, 14, 11, 12})
            CHECK(test::sameBits(read(cache, frame), frames[static_cast<size_t>(frame - 10)]));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)read(cache, 15); }),
                   Contains("a.pc2: frame 15: is not in the cache (expected one of its frames 10 to 14)"));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)read(cache, 9); }), Contains("frame 9"));
    }
    SECTION("PC2 with half a frame per sample: only the whole frames are frames") {
        test::writeText(dir / "a.pc2", test::pc2Bytes(-1.0f, 0.5f, frames));
        io::PointCache cache(dir / "a.pc2");
        CHECK(cache.frames() == std::vector<int>{-1, 0, 1});
        CHECK(test::sameBits(read(cache, 0), frames[2]));
        CHECK(test::sameBits(read(cache, 1), frames[4]));
        CHECK(cache.sampleFrame(1) == -0.5);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)read(cache, 2); }),
                   Contains("expected one of its frames -1 to 1 every 0.5"));
    }
    SECTION("PC2 sampled every other frame: a job's frame between samples is named with the step") {
        test::writeText(dir / "a.pc2", test::pc2Bytes(1.0f, 2.0f, frames));  // frames 1, 3, 5, 7, 9
        io::AnimatedPositions positions(dir / "a.pc2", "--deformed");
        const std::vector<int> wanted{1, 2};
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { positions.requireFrames(wanted); }),
            Contains("a.pc2: frame 2: is not in the cache (expected one of its frames 1 to 9 every 2)"));
    }
    SECTION(
        "PC2 sampled closer than a frame's tolerance: each whole frame listed once, read from its nearest "
        "sample") {
        test::writeText(dir / "a.pc2",
                        test::pc2Bytes(1.99998f, 1.0e-5f, frames));  // samples 1.99998 to 2.00002
        io::PointCache cache(dir / "a.pc2");
        CHECK(cache.frames() == std::vector<int>{2});
        CHECK(cache.sampleOf(2) == 2);
        CHECK(test::sameBits(read(cache, 2), frames[2]));
        // All three samples (-5e-5, -4e-5, -3e-5) within the tolerance of frame 0, the nearest the last: the
        // nearest sample to a frame lies past the cache's end when counted from its start.
        const std::vector<std::vector<glm::vec3>> three(frames.begin(), frames.begin() + 3);
        test::writeText(dir / "b.pc2", test::pc2Bytes(-5.0e-5f, 1.0e-5f, three));
        io::PointCache before(dir / "b.pc2");
        CHECK(before.frames() == std::vector<int>{0});
        CHECK(before.sampleOf(0) == 2);
        CHECK(test::sameBits(read(before, 0), frames[2]));
    }
    SECTION(
        "PC2 sampled a third or a tenth of a frame, stored as floats: every whole frame of a long cache") {
        // 0.33333334f and 0.100000001f times a sample's index drift past the frame tolerance after about
        // 10^4 samples: the cache reads as the 1/3 and 0.1 its writer meant.
        for (const auto& [sampling, perFrame] : {std::pair{1.0f / 3.0f, 3}, std::pair{0.1f, 10}}) {
            INFO("sampling " << sampling);
            const int samples = 5000 * perFrame;
            test::writeText(dir / "long.pc2", test::pc2Bytes(1.0f, sampling, randomFrames(samples, 1, 5)));
            io::PointCache cache(dir / "long.pc2");
            const std::vector<int> whole = cache.frames();
            REQUIRE(whole.size() == 5000);
            CHECK((whole.front() == 1 && whole.back() == 5000));
            for (const int frame : {1, 3356, 4999, 5000})
                CHECK(cache.sampleOf(frame) == (frame - 1) * perFrame);
        }
        // A sampling that is no 1/n reads as its shortest decimal: 0.4f as 0.4, frames 1, 3, 5, ...
        test::writeText(dir / "four.pc2", test::pc2Bytes(1.0f, 0.4f, randomFrames(25001, 1, 6)));
        io::PointCache four(dir / "four.pc2");
        CHECK(four.sampling() == 0.4);
        CHECK(four.frames().size() == 5001);
        CHECK(four.sampleOf(10001) == 25000);
    }
    SECTION("PC2 with the first frame set by the reader") {
        test::writeText(dir / "a.pc2", test::pc2Bytes(10.0f, 1.0f, frames));
        io::PointCache cache(dir / "a.pc2", 1.0);
        CHECK(cache.frames() == std::vector<int>{1, 2, 3, 4, 5});
        CHECK(test::sameBits(read(cache, 1), frames[0]));
    }
    SECTION("MDD: big-endian, frames from 1 unless told, times checked") {
        test::writeText(dir / "a.MDD", test::mddBytes({0.0f, 0.04f, 0.08f, 0.12f, 0.16f}, frames));
        io::PointCache cache(dir / "a.MDD");
        CHECK(cache.format() == io::PointCacheFormat::Mdd);
        CHECK(cache.frames() == std::vector<int>{1, 2, 3, 4, 5});
        CHECK(cache.times() == std::vector<float>{0.0f, 0.04f, 0.08f, 0.12f, 0.16f});
        for (int frame = 1; frame <= 5; ++frame)
            CHECK(test::sameBits(read(cache, frame), frames[static_cast<size_t>(frame - 1)]));
        io::PointCache fromZero(dir / "a.MDD", 0.0);
        CHECK(fromZero.frames() == std::vector<int>{0, 1, 2, 3, 4});
        CHECK(test::sameBits(read(fromZero, 4), frames[4]));
    }
}

TEST_CASE("point cache: the writer's files parse by hand, bit for bit, in both formats",
          "[io][point_cache]") {
    const test::TempDir dir;
    const auto frames = randomFrames(4, 9, 23);
    for (const char* name : {"w.pc2", "w.mdd"}) {
        CAPTURE(name);
        const fs::path path = dir / name;
        io::PointCacheWriter writer(path, 9, 4, 3, 25.0);
        for (const auto& frame : frames)
            writer.append(frame);
        CHECK_FALSE(fs::exists(path));  // nothing at the path before finish()
        writer.finish();
        const std::string expected =
            std::string(name) == "w.pc2"
                ? test::pc2Bytes(3.0f, 1.0f, frames)
                : test::mddBytes({0.0f, 1.0f / 25.0f, 2.0f / 25.0f, 3.0f / 25.0f}, frames);
        CHECK(test::readText(path) == expected);
        io::PointCache cache(path, std::string(name) == "w.mdd" ? std::optional<double>(3.0) : std::nullopt);
        CHECK(cache.frames() == std::vector<int>{3, 4, 5, 6});
    }
    CHECK(test::filesIn(dir.path()) == std::vector<fs::path>{"w.mdd", "w.pc2"});  // no staging file left
}

TEST_CASE("point cache: a writer that does not finish leaves the earlier file and no other",
          "[io][point_cache]") {
    const test::TempDir dir;
    const auto frames = randomFrames(2, 3, 5);
    test::writeText(dir / "c.pc2", "earlier");
    {
        io::PointCacheWriter writer(dir / "c.pc2", 3, 2, 1);
        writer.append(frames[0]);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { writer.finish(); }),
                   Contains("c.pc2: has 1 of its 2 frames"));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { writer.append(std::vector<glm::vec3>(4)); }),
                   Contains("c.pc2: frame 2: has 4 vertices (expected 3 vertices"));
        std::vector<glm::vec3> bad = frames[1];
        bad[2].y = std::numeric_limits<float>::quiet_NaN();
        CHECK_THAT(test::errorOf<InvalidInput>([&] { writer.append(bad); }),
                   Contains("c.pc2: frame 2: vertex 2: is not finite"));
    }
    CHECK(test::readText(dir / "c.pc2") == "earlier");
    CHECK(test::filesIn(dir.path()) == std::vector<fs::path>{"c.pc2"});
    CHECK_THAT(test::errorOf<InvalidInput>([&] { io::PointCacheWriter(dir / "c.abc", 3, 2, 1); }),
               Contains("c.abc") && Contains(".pc2 or .mdd"));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { io::PointCacheWriter(dir / "c.pc2", 3, 0, 1); }),
               Contains("at least one frame and one vertex"));
    // A PC2's start frame is a float: 2^24 + 1 would read back as 2^24.
    CHECK_THAT(test::errorOf<InvalidInput>([&] { io::PointCacheWriter(dir / "c.pc2", 3, 2, (1 << 24) + 1); }),
               Contains("c.pc2: first frame: is 16777217") && Contains("-16777216 to 16777216"));
    CHECK_THAT(
        test::errorOf<InvalidInput>([&] { io::PointCacheWriter(dir / "c.pc2", 3, 2, -(1 << 24) - 1); }),
        Contains("first frame: is -16777217"));
    CHECK(test::filesIn(dir.path()) == std::vector<fs::path>{"c.pc2"});
}

TEST_CASE("point cache: start frames at the PC2 limit and MDD's far frames read back", "[io][point_cache]") {
    const test::TempDir dir;
    const auto frames = randomFrames(2, 3, 9);
    for (const int first : {1 << 24, -(1 << 24), (1 << 24) + 1}) {
        for (const char* name : {"l.pc2", "l.mdd"}) {
            if (first == (1 << 24) + 1 && std::string(name) == "l.pc2") continue;  // refused above
            {
                io::PointCacheWriter writer(dir / name, 3, 2, first);
                writer.append(frames[0]);
                writer.append(frames[1]);
                writer.finish();
            }
            io::PointCache cache(dir / name,
                                 std::string(name) == "l.mdd" ? std::optional<double>(first) : std::nullopt);
            CAPTURE(name, first);
            CHECK(cache.frames() == std::vector<int>{first, first + 1});
            std::vector<glm::vec3> got;
            cache.read(first + 1, got);
            CHECK(got == frames[1]);
        }
    }
}

TEST_CASE("point cache: one cache read from several threads at once gives each its frame",
          "[io][point_cache]") {
    // Frame f of the cache holds the value f at every coordinate; 4 threads read 200 frames in turn from
    // one PointCache, each checking what it got against the frame it asked for.
    const test::TempDir dir;
    const int32_t vertices = 20000, count = 8;
    {
        io::PointCacheWriter writer(dir / "t.pc2", vertices, count, 1);
        for (int f = 1; f <= count; ++f)
            writer.append(std::vector<glm::vec3>(vertices, glm::vec3(static_cast<float>(f))));
        writer.finish();
    }
    io::PointCache cache(dir / "t.pc2");
    std::atomic<int> wrong{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            std::vector<glm::vec3> points;
            for (int k = 0; k < 50; ++k) {
                const int frame = 1 + (k + t) % count;
                cache.read(frame, points);
                for (const glm::vec3& p : points)
                    if (p != glm::vec3(static_cast<float>(frame))) {
                        ++wrong;
                        break;
                    }
            }
        });
    }
    for (std::thread& thread : threads)
        thread.join();
    CHECK(wrong == 0);
}

TEST_CASE("point cache: bad caches are refused naming the file, the frame and the vertex",
          "[io][point_cache]") {
    const test::TempDir dir;
    const auto frames = randomFrames(3, 4, 7);
    const fs::path pc2 = dir / "bad.pc2", mdd = dir / "bad.mdd";
    auto open = [](const fs::path& path) { io::PointCache cache(path); };

    SECTION("truncated: the first incomplete frame is named") {
        const std::string whole = test::pc2Bytes(1.0f, 1.0f, frames);
        test::writeText(pc2, whole.substr(0, whole.size() - 5));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("bad.pc2: frame 3: is cut short: the file has 171 bytes, 2 whole frames") &&
                       Contains("expected 176 bytes for 3 frames of 4 vertices"));
        test::writeText(pc2, whole.substr(0, 20));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("bad.pc2: header: is cut short"));
        const std::string m = test::mddBytes({0.0f, 1.0f, 2.0f}, frames);
        test::writeText(mdd, m.substr(0, 12));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(mdd); }),
                   Contains("bad.mdd: frame times: are cut short"));
    }
    SECTION("overlong, wrong magic, wrong version, bad sampling, decreasing times") {
        test::writeText(pc2, test::pc2Bytes(1.0f, 1.0f, frames) + "xx");
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("has 2 bytes after its last frame"));
        std::string wrong = test::pc2Bytes(1.0f, 1.0f, frames);
        wrong[0] = 'Q';
        test::writeText(pc2, wrong);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("does not start with POINTCACHE2"));
        test::writeText(pc2, test::pc2Bytes(1.0f, 1.0f, frames, 2));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("has version 2 (expected PC2 version 1)"));
        test::writeText(pc2, test::pc2Bytes(1.0f, 0.0f, frames));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }), Contains("has the sampling 0"));
        test::writeText(pc2, test::pc2Bytes(1.0f, 1.0f, {}));
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }), Contains("has 0 vertices and 0 frames"));
        // No frame at all: nothing a job could read (the writer refuses to write one).
        std::string empty = test::pc2Bytes(1.0f, 1.0f, {});
        empty.replace(16, 4, std::string("\x03\0\0\0", 4));  // 3 vertices, 0 samples
        test::writeText(pc2, empty);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("bad.pc2: header: has 3 vertices and 0 frames (expected at least one vertex and "
                            "one frame)"));
        std::string emptyMdd;
        test::appendWord(emptyMdd, int32_t{0}, true);
        test::appendWord(emptyMdd, int32_t{3}, true);
        test::writeText(mdd, emptyMdd);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(mdd); }),
                   Contains("bad.mdd: header: has 3 vertices and 0 frames"));
        // The other byte order: a big-endian PC2 and a little-endian MDD, every word of the file reversed.
        const auto reversedWords = [](std::string bytes, size_t from) {
            for (size_t k = from; k + 4 <= bytes.size(); k += 4)
                std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(k),
                             bytes.begin() + static_cast<std::ptrdiff_t>(k) + 4);
            return bytes;
        };
        test::writeText(pc2, reversedWords(test::pc2Bytes(1.0f, 1.0f, frames), 12));
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { open(pc2); }),
            Contains("bad.pc2: header: has version 16777216, which is version 1 in big-endian byte order "
                     "(expected PC2 version 1 in little-endian byte order"));
        test::writeText(mdd, reversedWords(test::mddBytes({0.0f, 1.0f, 2.0f}, frames), 0));
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { open(mdd); }),
            Contains("bad.mdd: header: reads as 3 frames of 4 vertices, as the file's size says, only in "
                     "little-endian byte order (expected MDD's big-endian byte order"));
        test::writeText(mdd, test::mddBytes({0.0f, 2.0f, 1.0f}, frames));
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { open(mdd); }),
            Contains("bad.mdd: frame time 2: is 1 after 2 (expected finite times in seconds, increasing)"));
    }
    SECTION("a header whose frames' bytes pass 2^64 is cut short, not read") {
        // 2147380029 vertices x 715862424 samples x 12 bytes = 2^64 + 11936: in 64-bit arithmetic the 32-byte
        // header and 11936 bytes of data look like the whole file, while the first frame alone is 25 GB.
        constexpr int32_t vertices = 2147380029, samples = 715862424;
        static_assert(static_cast<uint64_t>(vertices) * 12u * static_cast<uint64_t>(samples) ==
                      static_cast<uint64_t>(11936));  // unsigned arithmetic wraps around 2^64
        std::string bytes("POINTCACHE2", 11);
        bytes.push_back('\0');
        test::appendWord(bytes, int32_t{1}, false);
        test::appendWord(bytes, vertices, false);
        test::appendWord(bytes, 1.0f, false);
        test::appendWord(bytes, 1.0f, false);
        test::appendWord(bytes, samples, false);
        bytes.append(11936, '\0');
        test::writeText(pc2, bytes);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { open(pc2); }),
                   Contains("bad.pc2: frame 1: is cut short: the file has 11968 bytes, 0 whole frames") &&
                       Contains("expected more than 2^64 bytes for 715862424 frames of 2147380029 vertices"));
    }
    SECTION("a NaN or an infinity names the frame and the vertex when the frame is read") {
        auto nan = frames;
        nan[1][3].z = std::numeric_limits<float>::quiet_NaN();
        test::writeText(pc2, test::pc2Bytes(1.0f, 1.0f, nan));
        io::PointCache cache(pc2);
        CHECK(test::sameBits(read(cache, 1), frames[0]));  // the other frames read
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)read(cache, 2); }),
                   Contains("bad.pc2: frame 2: vertex 3: is (") && Contains("nan)") &&
                       Contains("expected finite coordinates"));
        auto inf = frames;
        inf[2][0].x = -std::numeric_limits<float>::infinity();
        test::writeText(mdd, test::mddBytes({0.0f, 1.0f, 2.0f}, inf));
        io::PointCache big(mdd);
        CHECK_THAT(test::errorOf<InvalidInput>([&] { (void)read(big, 3); }),
                   Contains("bad.mdd: frame 3: vertex 0: is (-inf"));
    }
    SECTION("a vertex count other than the rest mesh's, a frame outside the cache") {
        test::writeText(pc2, test::pc2Bytes(1.0f, 1.0f, frames));
        io::AnimatedPositions positions(pc2, "--deformed");
        const geom::Mesh rest = geom::makeGrid({2, 2, 1.0f, 1.0f});  // 9 vertices
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { positions.setReference(rest, "rest.obj"); }),
            Contains("bad.pc2: header: has 4 vertices per frame (expected 9 vertices, as the rest mesh "
                     "'rest.obj')"));
        const std::vector<int> wanted{2, 3, 4};
        CHECK_THAT(test::errorOf<InvalidInput>([&] { positions.requireFrames(wanted); }),
                   Contains("bad.pc2: frame 4: is not in the cache (expected one of its frames 1 to 3)"));
        CHECK(positions.frameName(2) == pc2.string() + " frame 2");
    }
    SECTION("missing file, and a path that is neither a sequence nor a cache") {
        CHECK_THAT(test::errorOf<IoError>([&] { open(dir / "none.pc2"); }),
                   Contains("none.pc2: does not exist"));
        CHECK_THAT(
            test::errorOf<InvalidInput>([&] { io::AnimatedPositions(dir / "anim.obj", "--deformed"); }),
            Contains("--deformed: ") && Contains("has no frame token and is no point cache") &&
                Contains("'anim.pc2', 'anim.mdd'"));
        CHECK_THAT(test::errorOf<InvalidInput>(
                       [&] { io::AnimatedPositions(dir / "a.####.obj", "--deformed", 1.0); }),
                   Contains("is an OBJ sequence, given a cache's first frame 1"));
    }
}

namespace {

// The test's own measure of a frame against its rest mesh: every corner edge of every face (a shared edge
// counted once per face) with a rest length, torn when longer than 4 times its rest length scaled by the
// growth of the RMS distance from the centroid (mean |p|^2 - |mean p|^2, in long double).
struct OwnTear {
    int torn = 0, edges = 0;
};
OwnTear ownTear(const geom::Mesh& rest, const std::vector<glm::vec3>& frame) {
    const auto spread = [](std::span<const glm::vec3> p) {
        long double sx = 0, sy = 0, sz = 0, square = 0;
        for (const glm::vec3& q : p) {
            sx += q.x;
            sy += q.y;
            sz += q.z;
            square += static_cast<long double>(q.x) * q.x + static_cast<long double>(q.y) * q.y +
                      static_cast<long double>(q.z) * q.z;
        }
        const long double n = p.size();
        return std::sqrt(square / n - (sx * sx + sy * sy + sz * sz) / (n * n));
    };
    const long double scale = spread(frame) / spread(rest.points());
    const auto length = [](const glm::vec3& a, const glm::vec3& b) {
        return std::sqrt(static_cast<long double>(b.x - a.x) * (b.x - a.x) +
                         static_cast<long double>(b.y - a.y) * (b.y - a.y) +
                         static_cast<long double>(b.z - a.z) * (b.z - a.z));
    };
    OwnTear out;
    for (int32_t f = 0; f < rest.numFaces(); ++f) {
        const auto face = rest.face(f);
        for (size_t c = 0; c < face.size(); ++c) {
            const int32_t a = face[c], b = face[(c + 1) % face.size()];
            const long double r = length(rest.points()[a], rest.points()[b]);
            if (r <= 0) continue;
            ++out.edges;
            if (length(frame[a], frame[b]) > 4 * scale * r) ++out.torn;
        }
    }
    return out;
}

// A smooth motion of `rest`: a bend about the y axis, a twist about z, then a rotation, a uniform scale and a
// translation, all random (a cache in other units, moved or turned, as well as deformed).
std::vector<glm::vec3> moved(const geom::Mesh& rest, std::mt19937& rng) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    const float bend = unit(rng), twist = 2.0f * unit(rng), scale = std::pow(10.0f, 2.0f * unit(rng));
    const glm::vec3 axis = glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)) + glm::vec3(0, 0, 2.5f));
    const float angle = 3.0f * unit(rng);
    const glm::vec3 offset(10 * unit(rng), 10 * unit(rng), 10 * unit(rng));
    std::vector<glm::vec3> out;
    for (glm::vec3 p : rest.points()) {
        const float t = twist * p.z, c = std::cos(t), s = std::sin(t);
        p = {c * p.x - s * p.y, s * p.x + c * p.y, p.z + bend * p.x * p.x};
        // Rodrigues' rotation about `axis`.
        const float ca = std::cos(angle), sa = std::sin(angle);
        p = p * ca + glm::cross(axis, p) * sa + axis * glm::dot(axis, p) * (1.0f - ca);
        out.push_back(scale * p + offset);
    }
    return out;
}

}  // namespace

TEST_CASE(
    "vertex order: frames of the rest mesh's motion pass, frames in another order are torn (random cases)",
    "[io][point_cache]") {
    const geom::Mesh grid = geom::makeGrid({24, 24, 1.0f, 1.0f});
    const geom::Mesh sphere = geom::makeSphere({1.0f, 32, 16});
    std::mt19937 rng(2026);
    for (const geom::Mesh* rest : {&grid, &sphere}) {
        // Both meshes have fewer corners than the check samples: it judges every corner edge, as the test.
        REQUIRE(rest->faceIndices().size() <= static_cast<size_t>(io::VertexOrderCheck::kSampledEdges));
        const io::VertexOrderCheck check(*rest);
        for (int trial = 0; trial < 50; ++trial) {
            INFO((rest == &grid ? "grid" : "sphere") << ", trial " << trial);
            std::vector<glm::vec3> frame = moved(*rest, rng);
            const OwnTear own = ownTear(*rest, frame);
            CHECK(own.torn == 0);
            CHECK_FALSE(check.tear(frame).has_value());
            // A quarter of the points collapsed onto one of them (a part scaled to nothing by its bone).
            for (size_t k = 1; k < frame.size() / 4; ++k)
                frame[k] = frame[0];
            CHECK(4 * ownTear(*rest, frame).torn <= ownTear(*rest, frame).edges);
            CHECK_FALSE(check.tear(frame).has_value());
            // The same motion, its vertices shuffled.
            std::vector<glm::vec3> shuffled = moved(*rest, rng);
            std::shuffle(shuffled.begin(), shuffled.end(), rng);
            const OwnTear mixed = ownTear(*rest, shuffled);
            REQUIRE(4 * mixed.torn > mixed.edges);
            const std::optional<io::VertexOrderCheck::Tear> tear = check.tear(shuffled);
            REQUIRE(tear.has_value());
            CHECK(tear->edges == mixed.edges);
            // The same edges and rule, computed in double against long double: an edge within rounding of
            // the threshold may fall either side.
            CHECK(std::abs(tear->torn - mixed.torn) <= 1);
        }
    }
    // Nothing judged: too few edges, or the frame all in one point.
    const geom::Mesh quad = geom::makeGrid({1, 1, 1.0f, 1.0f});
    std::vector<glm::vec3> reversed(quad.points().rbegin(), quad.points().rend());
    CHECK_FALSE(io::VertexOrderCheck(quad).tear(reversed).has_value());
    const std::vector<glm::vec3> point(grid.points().size(), glm::vec3(1.0f));
    CHECK_FALSE(io::VertexOrderCheck(grid).tear(point).has_value());
    // A frame of another size is an error, not read past its end.
    const std::vector<glm::vec3> shorter(grid.points().begin(), grid.points().end() - 1);
    CHECK_THROWS_WITH(io::VertexOrderCheck(grid).tear(shorter),
                      Catch::Contains("has 624 points (expected 625"));
}

TEST_CASE(
    "vertex order: a cache frame in another vertex order is refused naming the cache, frame and rest mesh",
    "[io][point_cache]") {
    const test::TempDir dir;
    const geom::Mesh rest = geom::makeGrid({12, 12, 1.0f, 1.0f});
    std::vector<std::vector<glm::vec3>> frames(
        3, std::vector<glm::vec3>(rest.points().begin(), rest.points().end()));
    for (glm::vec3& p : frames[1])
        p.z = 0.2f * std::sin(3.0f * p.x);  // a wave: the order kept
    std::mt19937 rng(7);
    std::shuffle(frames[2].begin(), frames[2].end(), rng);
    const fs::path pc2 = dir / "anim.pc2";
    test::writeText(pc2, test::pc2Bytes(1.0f, 1.0f, frames));
    io::AnimatedPositions positions(pc2, "--deformed");
    positions.setReference(rest, "rest.fbx");
    std::vector<glm::vec3> points;
    positions.read(1, points);
    CHECK(test::sameBits(points, frames[0]));
    positions.read(2, points);
    CHECK(test::sameBits(points, frames[1]));
    const OwnTear own = ownTear(rest, frames[2]);
    const std::string percent = std::to_string(static_cast<int>(std::lround(100.0 * own.torn / own.edges)));
    CHECK_THAT(test::errorOf<InvalidInput>([&] { positions.read(3, points); }),
               Contains("anim.pc2: frame 3: stretches " + percent + "% of " + std::to_string(own.edges) +
                        " edges of the rest mesh 'rest.fbx' beyond 4 times their rest length") &&
                   Contains("its vertices are not in the rest mesh's order (expected the rest mesh's vertex "
                            "order; an FBX or Collada rest mesh is welded and renumbered on reading"));
    // Without a reference (PointCache alone, `deformkit info`) the frame is read as it is.
    io::PointCache cache(pc2);
    CHECK(test::sameBits(read(cache, 3), frames[2]));
}

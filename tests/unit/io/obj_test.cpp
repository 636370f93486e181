#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <random>

#include "deformkit/error.h"
#include "deformkit/geom/primitives.h"
#include "deformkit/io/obj.h"
#include "test_support.h"

using deformkit::InvalidInput;
using deformkit::IoError;
using deformkit::ParseError;
using deformkit::geom::Mesh;
using namespace deformkit::io;
namespace fs = std::filesystem;
namespace test = deformkit::test;

namespace {

std::vector<int32_t> toVector(std::span<const int32_t> s) {
    return {s.begin(), s.end()};
}

std::vector<uint32_t> bitsOf(std::span<const glm::vec3> points) {
    std::vector<uint32_t> bits;
    for (const auto& p : points) {
        for (int k = 0; k < 3; ++k)
            bits.push_back(std::bit_cast<uint32_t>(p[k]));
    }
    return bits;
}

std::vector<uint32_t> bitsOf(std::span<const glm::vec2> uvs) {
    std::vector<uint32_t> bits;
    for (const auto& t : uvs) {
        for (int k = 0; k < 2; ++k)
            bits.push_back(std::bit_cast<uint32_t>(t[k]));
    }
    return bits;
}

// Same data to the bit: positions, UVs, connectivity, groups.
void checkIdentical(const ObjContent& read, const Mesh& mesh, const std::vector<FaceGroup>& groups) {
    CHECK(bitsOf(read.mesh.points()) == bitsOf(mesh.points()));
    CHECK(bitsOf(read.mesh.uvs()) == bitsOf(mesh.uvs()));
    CHECK(toVector(read.mesh.faceCounts()) == toVector(mesh.faceCounts()));
    CHECK(toVector(read.mesh.faceIndices()) == toVector(mesh.faceIndices()));
    CHECK(toVector(read.mesh.uvIndices()) == toVector(mesh.uvIndices()));
    REQUIRE(read.groups.size() == groups.size());
    for (size_t g = 0; g < groups.size(); ++g) {
        CHECK(read.groups[g].name == groups[g].name);
        CHECK(read.groups[g].faces == groups[g].faces);
    }
}

ObjContent roundTrip(const test::TempDir& dir, const Mesh& mesh, const std::vector<FaceGroup>& groups = {}) {
    const fs::path path = dir / "round_trip.obj";
    writeObj(path, mesh, groups);
    return readObj(path);
}

// Random float32 values over many binades, with the awkward ones: signed zeros, subnormals, extremes.
float randomFloat(std::mt19937& rng) {
    std::uniform_int_distribution<int> kind(0, 9);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::uniform_int_distribution<int> exponent(-40, 38);
    switch (kind(rng)) {
        case 0:
            return -0.0f;
        case 1:
            return std::numeric_limits<float>::denorm_min() * static_cast<float>(rng() % 1000 + 1);
        case 2:
            return std::numeric_limits<float>::max() * unit(rng);
        case 3:
            return std::bit_cast<float>(static_cast<uint32_t>(rng() & 0x7f7fffffu));
        default:
            return unit(rng) * std::pow(10.0f, static_cast<float>(exponent(rng) / 4));
    }
}

// A mesh of random n-gons (3 to 8 distinct vertices) with random UVs and overlapping groups.
std::pair<Mesh, std::vector<FaceGroup>> randomMesh(uint32_t seed) {
    std::mt19937 rng(seed);
    Mesh::Data d;
    const int32_t numVertices = 300, numUVs = 200, numFaces = 500;
    for (int32_t v = 0; v < numVertices; ++v)
        d.points.emplace_back(randomFloat(rng), randomFloat(rng), randomFloat(rng));
    for (int32_t t = 0; t < numUVs; ++t)
        d.uvs.emplace_back(randomFloat(rng), randomFloat(rng));
    std::vector<int32_t> order(numVertices);
    for (int32_t v = 0; v < numVertices; ++v)
        order[v] = v;
    for (int32_t f = 0; f < numFaces; ++f) {
        const int32_t n = 3 + static_cast<int32_t>(rng() % 6);
        std::shuffle(order.begin(), order.end(), rng);
        d.faceCounts.push_back(n);
        for (int32_t k = 0; k < n; ++k) {
            d.faceIndices.push_back(order[k]);
            d.uvIndices.push_back(static_cast<int32_t>(rng() % numUVs));
        }
    }
    // Group k starts at face 40 k, so first faces come in group order, as a reader lists them.
    std::vector<FaceGroup> groups;
    for (int32_t g = 0; g < 6; ++g) {
        FaceGroup group{"group_" + std::to_string(g), {40 * g}};
        for (int32_t f = 40 * g + 1; f < numFaces; ++f) {
            if (rng() % 3 == 0) group.faces.push_back(f);
        }
        groups.push_back(group);
    }
    return {Mesh(std::move(d), "random"), groups};
}

}  // namespace

TEST_CASE("obj: hand-written file read element by element", "[io][obj]") {
    const std::string text =
        "# a triangle, a quad and a pentagon\n"
        "v 0 0 0\n"
        "v 1 0 0\n"
        "v 1 1 0\n"
        "v 0 1 0\n"
        "v 2 0.5 -1.25e-1\n"
        "v -1 0.5 3\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "f 1/1 2/2 3/3\n"
        "f 1/1 2/2 3/3 4/4\n"
        "f 2/2 5/1 3/3 4/4 6/2\n";
    const ObjContent c = parseObj(text, "three.obj");
    const Mesh& m = c.mesh;
    REQUIRE(m.numVertices() == 6);
    CHECK(m.points()[4] == glm::vec3(2.0f, 0.5f, -0.125f));
    CHECK(m.points()[5] == glm::vec3(-1.0f, 0.5f, 3.0f));
    CHECK(toVector(m.faceCounts()) == std::vector<int32_t>{3, 4, 5});
    CHECK(toVector(m.faceIndices()) == std::vector<int32_t>{0, 1, 2, 0, 1, 2, 3, 1, 4, 2, 3, 5});
    REQUIRE(m.hasUVs());
    REQUIRE(m.numUVs() == 4);
    CHECK(m.uvs()[2] == glm::vec2(1.0f, 1.0f));
    CHECK(toVector(m.uvIndices()) == std::vector<int32_t>{0, 1, 2, 0, 1, 2, 3, 1, 0, 2, 3, 1});
    CHECK(c.groups.empty());
}

TEST_CASE("obj: relative indices count back from the last vertex defined so far", "[io][obj]") {
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\n"
        "f -3/-3 -2/-2 -1/-1\n"
        "v 0 1 0\n"
        "vt 0 1\n"
        "f 1/1 -2/-2 -1/-1\n"  // -2 is now vertex 3 and uv 3
        "v 2 2 0\n"
        "f -1/1 -3/2 -2/-1\n";
    const Mesh m = parseObj(text, "relative.obj").mesh;
    CHECK(toVector(m.faceIndices()) == std::vector<int32_t>{0, 1, 2, 0, 2, 3, 4, 2, 3});
    CHECK(toVector(m.uvIndices()) == std::vector<int32_t>{0, 1, 2, 0, 2, 3, 0, 1, 3});
}

TEST_CASE("obj: every corner form, normals checked but dropped", "[io][obj]") {
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vn 0 0 1\n"
        "f 1 2 3\n"
        "f 1//1 3//1 4//-1\n";
    const Mesh a = parseObj(text, "plain.obj").mesh;
    CHECK_FALSE(a.hasUVs());
    CHECK(toVector(a.faceIndices()) == std::vector<int32_t>{0, 1, 2, 0, 2, 3});

    const std::string withUVs =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0.25 0.75\nvt 0.5 0.5\nvn 0 0 1\n"
        "f 1/2/1 2/1/1 3/2/1\n"
        "f 3/1 2/2 1/1\n";
    const Mesh b = parseObj(withUVs, "uv.obj").mesh;
    CHECK(toVector(b.uvIndices()) == std::vector<int32_t>{1, 0, 1, 0, 1, 0});
    CHECK(b.uvs()[0] == glm::vec2(0.25f, 0.75f));
}

TEST_CASE("obj: groups from g and o", "[io][obj]") {
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "f 1 2 3\n"    // face 0: before any group, in none
        "g default\n"  // names no face: no group
        "g arm\n"
        "f 1 3 4\n"  // face 1: arm
        "o body\n"
        "f 1 2 4\n"  // face 2: body (o with no g after it)
        "o ignored\n"
        "g leg arm\n"
        "f 2 3 4\n"  // face 3: leg and arm (g after o wins)
        "g\n"
        "f 4 3 2\n"  // face 4: no group
        "g arm arm\n"
        "f 3 2 1\n";  // face 5: arm, once
    const ObjContent c = parseObj(text, "groups.obj");
    CHECK(c.mesh.numFaces() == 6);
    REQUIRE(c.groups.size() == 3);
    CHECK(c.groups[0].name == "arm");
    CHECK(c.groups[0].faces == std::vector<int32_t>{1, 3, 5});
    CHECK(c.groups[1].name == "body");
    CHECK(c.groups[1].faces == std::vector<int32_t>{2});
    CHECK(c.groups[2].name == "leg");
    CHECK(c.groups[2].faces == std::vector<int32_t>{3});
}

TEST_CASE("obj: CRLF, comments, blank lines, continuations and ignored statements", "[io][obj]") {
    const std::string text =
        "# exported\r\n"
        "mtllib scene file.mtl\r\n"
        "\r\n"
        "   \t\r\n"
        "v 0 0 0 1\r\n"               // w
        "v +1.5 0 0 0.1 0.2 0.3\r\n"  // colour
        "v 1 \\\r\n"
        "  1e0 0 # trailing comment\r\n"
        "v 0 1 0\r\n"
        "vt 0 0 0\r\n"
        "vt 1 0\r\n"
        "vt 1 1\r\n"
        "vt 0 1\r\n"
        "vn 0 0 1\r\n"
        "usemtl skin\r\n"
        "s off\r\n"
        "l 1 2\r\n"
        "p 1\r\n"
        "f\t1/1/1 2/2/1 \\\n"
        "3/3/1 4/4/1\r\n"
        "\r\n";
    const Mesh m = parseObj(text, "crlf.obj").mesh;
    REQUIRE(m.numVertices() == 4);
    CHECK(m.points()[1] == glm::vec3(1.5f, 0.0f, 0.0f));
    CHECK(m.points()[2] == glm::vec3(1.0f, 1.0f, 0.0f));
    CHECK(toVector(m.faceCounts()) == std::vector<int32_t>{4});
    CHECK(toVector(m.faceIndices()) == std::vector<int32_t>{0, 1, 2, 3});
    CHECK(m.numUVs() == 4);
}

TEST_CASE("obj: errors name the file, the line and what was expected", "[io][obj][errors]") {
    const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\n";
    SECTION("empty file") {
        CHECK_THROWS_AS(parseObj("", "empty.obj"), ParseError);
        CHECK_THROWS_WITH(parseObj("", "empty.obj"), Catch::Contains("empty.obj: ") &&
                                                         Catch::Contains("contains no faces") &&
                                                         Catch::Contains("expected at least one 'f'"));
    }
    SECTION("vertices but no faces") {
        CHECK_THROWS_WITH(parseObj(quad, "points.obj"), Catch::Contains("points.obj") &&
                                                            Catch::Contains("contains no faces") &&
                                                            Catch::Contains("3 vertices"));
    }
    SECTION("malformed number") {
        CHECK_THROWS_AS(parseObj("v 0 0 0\nv 1 0.5x 0\n", "bad.obj"), ParseError);
        CHECK_THROWS_WITH(parseObj("v 0 0 0\nv 1 0.5x 0\n", "bad.obj"),
                          Catch::Contains("bad.obj: line 2: malformed number '0.5x'") &&
                              Catch::Contains("expected v x y z"));
        CHECK_THROWS_WITH(
            parseObj(quad + "vt 0 zero\n", "bad.obj"),
            Catch::Contains("line 4: malformed number 'zero'") && Catch::Contains("expected vt u v"));
    }
    SECTION("too few coordinates") {
        CHECK_THROWS_WITH(parseObj("v 0 0\n", "short.obj"),
                          Catch::Contains("short.obj: line 1: vertex has 2 coordinates") &&
                              Catch::Contains("expected v x y z"));
    }
    SECTION("too many values") {
        CHECK_THROWS_WITH(
            parseObj("v 0 0 0 1 2 3 4 5\n", "long.obj"),
            Catch::Contains("long.obj: line 1: unexpected '5'") && Catch::Contains("expected v x y z"));
    }
    SECTION("index 0") {
        CHECK_THROWS_AS(parseObj(quad + "f 1 2 0\n", "zero.obj"), InvalidInput);
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2 0\n", "zero.obj"),
                          Catch::Contains("zero.obj: line 4: vertex index 0 is not valid") &&
                              Catch::Contains("expected an index in 1..3 or -3..-1"));
    }
    SECTION("positive index out of range") {
        CHECK_THROWS_AS(parseObj(quad + "f 1 2 4\n", "range.obj"), InvalidInput);
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2 4\n", "range.obj"),
                          Catch::Contains("range.obj: line 4: vertex index 4 is out of range: 3 vertices") &&
                              Catch::Contains("expected an index in 1..3 or -3..-1"));
        // A vertex defined after the face does not count.
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2 4\nv 0 1 0\n", "range.obj"), Catch::Contains("line 4"));
        CHECK_THROWS_WITH(
            parseObj(quad + "f 1 2 99999999999999999999999\n", "huge.obj"),
            Catch::Contains("huge.obj: line 4: vertex index 99999999999999999999999 is out of range"));
    }
    SECTION("negative index out of range") {
        CHECK_THROWS_WITH(parseObj(quad + "\n\nf -1 -2 -4\n", "negative.obj"),
                          Catch::Contains("negative.obj: line 6: vertex index -4 is out of range") &&
                              Catch::Contains("expected an index in 1..3 or -3..-1"));
    }
    SECTION("texture coordinate and normal indices out of range") {
        CHECK_THROWS_WITH(parseObj(quad + "vt 0 0\nf 1/1 2/2 3/1\n", "uv.obj"),
                          Catch::Contains("uv.obj: line 5: texture coordinate index 2 is out of range") &&
                              Catch::Contains("expected an index in 1..1 or -1..-1"));
        CHECK_THROWS_WITH(parseObj(quad + "f 1//1 2//1 3//1\n", "normal.obj"),
                          Catch::Contains("normal.obj: line 4: normal index 1 is out of range: 0 normals") &&
                              Catch::Contains("(expected a normal defined before it (none is yet))"));
        CHECK_THROWS_WITH(parseObj("f 1 2 3\nv 0 0 0\n", "first.obj"),
                          Catch::Contains("first.obj: line 1: vertex index 1 is out of range: 0 vertices") &&
                              Catch::Contains("(expected a vertex defined before it (none is yet))"));
    }
    SECTION("face with fewer than 3 vertices") {
        CHECK_THROWS_AS(parseObj(quad + "f 1 2\n", "two.obj"), InvalidInput);
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2\n", "two.obj"),
                          Catch::Contains("two.obj: line 4: face has 2 vertices") &&
                              Catch::Contains("expected at least 3 vertices"));
    }
    SECTION("a face with fewer than 3 distinct vertices") {
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2 -2\n", "twice.obj"),
                          Catch::Contains("twice.obj: line 4: face has fewer than 3 distinct vertices") &&
                              Catch::Contains("expected at least 3 distinct vertices"));
    }
    SECTION("UTF-16 text") {
        const std::string utf16("\xFE\xFF\0v\0 \0\x30", 8);
        CHECK_THROWS_AS(parseObj(utf16, "box_UTF16BE.obj"), ParseError);
        CHECK_THROWS_WITH(parseObj(utf16, "box_UTF16BE.obj"),
                          Catch::Contains("box_UTF16BE.obj: is UTF-16 text, which is not supported") &&
                              Catch::Contains("save the file as UTF-8"));
    }
    SECTION("UTF-8 with a byte order mark reads as without it") {
        const ObjContent plain = parseObj(quad + "f 1 2 3\n", "plain.obj");
        const ObjContent marked = parseObj("\xEF\xBB\xBF" + quad + "f 1 2 3\n", "bom.obj");
        CHECK(marked.mesh.points().size() == plain.mesh.points().size());
        CHECK(std::ranges::equal(marked.mesh.faceIndices(), plain.mesh.faceIndices()));
        CHECK_THROWS_WITH(parseObj("\xEF\xBB\xBFv 0 0\nx\n", "bom.obj"), Catch::Contains("bom.obj: line 1"));
    }
    SECTION("lines ended by CR alone (classic Mac OS) read as lines, their numbers kept") {
        std::string mac = quad + "f 1 2 3\n";
        std::replace(mac.begin(), mac.end(), '\n', '\r');
        const ObjContent plain = parseObj(quad + "f 1 2 3\n", "plain.obj");
        const ObjContent cr = parseObj(mac, "mac.obj");
        CHECK(test::sameBits(std::vector<glm::vec3>(cr.mesh.points().begin(), cr.mesh.points().end()),
                             std::vector<glm::vec3>(plain.mesh.points().begin(), plain.mesh.points().end())));
        CHECK(std::ranges::equal(cr.mesh.faceIndices(), plain.mesh.faceIndices()));
        CHECK_THROWS_WITH(parseObj("v 0 0 0\rv 1 0\r", "mac.obj"), Catch::Contains("mac.obj: line 2: "));
        // Mixed with LF and CR LF (files pasted together): a CR alone still ends its line, so no statement is
        // joined to the one before it and dropped.
        const ObjContent mixed =
            parseObj("v 0 0 0\nv 1 0 0\r\ns off\rv 1 1 0\r\nv 0 1 0\nf -4 -3 -2 -1\n", "mix.obj");
        CHECK(mixed.mesh.numVertices() == 4);
        CHECK(std::ranges::equal(mixed.mesh.faceIndices(), std::vector<int32_t>{0, 1, 2, 3}));
        CHECK_THROWS_WITH(parseObj("v 0 0 0\ns off\rv 1 0\r\n", "mix.obj"),
                          Catch::Contains("mix.obj: line 3: "));
        // CR CR LF (a file converted twice) is one line end, so line numbers stay the editor's.
        CHECK_THROWS_WITH(parseObj("v 0 0 0\r\r\nv 1 0 0\r\r\nv 1 0\r\r\n", "twice.obj"),
                          Catch::Contains("twice.obj: line 3: "));
    }
    SECTION("NaN and infinity as old Microsoft runtimes print them; a comment right after a number") {
        for (const char* text : {"1.#QNAN", "-1.#IND00", "1.#INF", "1.#SNAN", "-1.#INF0"}) {
            CHECK_THROWS_WITH(parseObj("v 0 0 0\nv 0 " + std::string(text) + " 0\n", "msvc.obj"),
                              Catch::Contains("msvc.obj: line 2: coordinate '" + std::string(text) +
                                              "' is NaN or infinite"));
        }
        const ObjContent commented = parseObj("v 0 0 1#top\nv 1 0 0.5# edge\nv 0 1 0\nf 1 2 3\n", "c.obj");
        CHECK(commented.mesh.points()[0] == glm::vec3(0, 0, 1));
        CHECK(commented.mesh.points()[1] == glm::vec3(1, 0, 0.5f));
    }
    SECTION("NaN and infinite coordinates") {
        CHECK_THROWS_AS(parseObj("v 0 nan 0\n", "nan.obj"), InvalidInput);
        CHECK_THROWS_WITH(parseObj("v 0 0 0\nv 0 nan 0\n", "nan.obj"),
                          Catch::Contains("nan.obj: line 2: coordinate 'nan' is NaN or infinite") &&
                              Catch::Contains("expected finite coordinates"));
        CHECK_THROWS_WITH(parseObj("v 0 0 -inf\n", "inf.obj"),
                          Catch::Contains("inf.obj: line 1: coordinate '-inf'"));
        CHECK_THROWS_WITH(parseObj(quad + "vt 0 inf\n", "inf.obj"),
                          Catch::Contains("line 4: coordinate 'inf'"));
        CHECK_THROWS_WITH(
            parseObj("v 1e39 0 0\n", "big.obj"),
            Catch::Contains("big.obj: line 1: number '1e39' is out of the range of a 32-bit float"));
    }
    SECTION("tiny numbers round to zero or a subnormal") {
        const Mesh m = parseObj("v 1e-50 -1e-60 1e-40\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "tiny.obj").mesh;
        CHECK(m.points()[0].x == 0.0f);
        CHECK(std::signbit(m.points()[0].y));
        CHECK(m.points()[0].z == 1e-40f);
        // Beyond a double's range as well; an ignored fourth value (w, or a colour) may overflow too.
        const Mesh tinier =
            parseObj("v 1e-400 -1e-400 0 1e400\nv 1 0 0 nan\nv 0 1 0\nf 1 2 3\n", "tiny.obj").mesh;
        CHECK(tinier.points()[0].x == 0.0f);
        CHECK(std::signbit(tinier.points()[0].y));
        CHECK_THROWS_WITH(
            parseObj("v 1e400 0 0\n", "big.obj"),
            Catch::Contains("big.obj: line 1: number '1e400' is out of the range of a 32-bit float"));
    }
    SECTION("some faces with UVs and some without: those without belong to no tile") {
        const std::string text = quad + "vt 0 0\nvt 1 0\n# faces\nf 1/1 2/2 3/1\nf 3 2 1\nf 1 3 2\n";
        const ObjContent c = parseObj(text, "mixed.obj");
        const Mesh& m = c.mesh;
        CHECK(m.hasUVs());
        CHECK(m.numFacesWithoutUVs() == 2);
        CHECK(c.facesWithoutUVs == 2);
        CHECK(c.firstLineWithoutUVs == 8);
        CHECK(m.faceHasUVs(0));
        CHECK_FALSE(m.faceHasUVs(1));
        CHECK(m.faceUVIndices(1).empty());
        CHECK(m.faceUdimTile(1) == 0);
        CHECK(m.udimTiles() == std::vector<int>{1001});
        const auto uvIndices = m.uvIndices();
        CHECK(std::vector<int32_t>(uvIndices.begin(), uvIndices.end()) ==
              std::vector<int32_t>{0, 1, 0, -1, -1, -1, -1, -1, -1});
        // Written back as read: "f 3 2 1" keeps no texture coordinates.
        const std::string written = formatObj(m);
        CHECK(written.find("f 1/1 2/2 3/1\nf 3 2 1\nf 1 3 2\n") != std::string::npos);
        const Mesh again = parseObj(written, "again.obj").mesh;
        const auto againIndices = again.uvIndices();
        CHECK(std::vector<int32_t>(againIndices.begin(), againIndices.end()) ==
              std::vector<int32_t>(uvIndices.begin(), uvIndices.end()));
        // A file where no face has UVs has none, whatever 'vt' lines it holds.
        CHECK_FALSE(parseObj(quad + "vt 0 0\nf 1 2 3\n", "nouv.obj").mesh.hasUVs());
        CHECK(parseObj(quad + "vt 0 0\nf 1 2 3\n", "nouv.obj").facesWithoutUVs == 0);
        // One face with UVs on some corners only is still an error.
        CHECK_THROWS_WITH(parseObj(quad + "vt 0 0\nf 1/1 2 3/1\n", "corner.obj"),
                          Catch::Contains("corner.obj: line 5: face corner 2 '2' has no texture coordinate"));
    }
    SECTION("a mesh built with UVs on some corners of a face is refused") {
        Mesh::Data d;
        d.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        d.faceCounts = {3};
        d.faceIndices = {0, 1, 2};
        d.uvs = {{0, 0}};
        d.uvIndices = {-1, 0, -1};
        CHECK_THROWS_WITH(Mesh(d, "m"), Catch::Contains("m: face 0: has UVs on some corners only (corner 1 "
                                                        "has uv index 0, corner 0 has none)"));
    }
    SECTION("malformed corner and unknown statement") {
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2/ 3\n", "corner.obj"),
                          Catch::Contains("corner.obj: line 4: malformed face corner '2/'") &&
                              Catch::Contains("expected a face corner v, v/vt, v//vn or v/vt/vn"));
        CHECK_THROWS_WITH(parseObj(quad + "f 1 2 3.0\n", "corner.obj"),
                          Catch::Contains("malformed face corner '3.0'"));
        CHECK_THROWS_AS(parseObj(quad + "F 1 2 3\n", "unknown.obj"), ParseError);
        CHECK_THROWS_WITH(parseObj(quad + "F 1 2 3\n", "unknown.obj"),
                          Catch::Contains("unknown.obj: line 4: unknown statement 'F'") &&
                              Catch::Contains("expected an OBJ statement"));
        // Lower-case statements of exporters' own extensions are skipped, as DCCs do.
        const ObjContent extended = parseObj(quad + "vc 1 0 0\nxyz_attr 3\nf 1 2 3\n", "extended.obj");
        CHECK(extended.mesh.numFaces() == 1);
        CHECK_THROWS_WITH(parseObj("v 0 0 0\n\x89PNG\x01\n", "binary.obj"),
                          Catch::Contains("line 2: unknown statement '\\x89PNG\\x01'"));
    }
    SECTION("a group name that would read back as a continuation") {
        CHECK_THROWS_WITH(parseObj(quad + "g arm\\ leg\nf 1 2 3\n", "slash.obj"),
                          Catch::Contains("slash.obj: line 4: group name 'arm\\' ends in a backslash"));
    }
    SECTION("line numbers count physical lines, CRLF and continuations included") {
        CHECK_THROWS_WITH(parseObj("v 0 0 \\\r\n0\r\nv 1 \\\n 0 \\\n x\r\n", "lines.obj"),
                          Catch::Contains("lines.obj: line 5: malformed number 'x'"));
    }
}

TEST_CASE("obj: readObj reports missing and unreadable files", "[io][obj][errors]") {
    test::TempDir dir;
    CHECK_THROWS_AS(readObj(dir / "missing.obj"), IoError);
    CHECK_THROWS_WITH(readObj(dir / "missing.obj"),
                      Catch::Contains((dir / "missing.obj").string() + ": cannot open: No such file") &&
                          Catch::Contains("expected an existing, readable OBJ file"));
    CHECK_THROWS_AS(readObj(dir.path()), IoError);

    const fs::path locked = dir / "locked.obj";
    test::writeText(locked, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    fs::permissions(locked, fs::perms::none);
    const bool unreadable = test::runUnprivileged([&] {
        try {
            (void)readObj(locked);
        } catch (const IoError& e) {
            return std::string(e.what()).find("Permission denied") != std::string::npos;
        }
        return false;
    });
    CHECK(unreadable);
    fs::permissions(locked, fs::perms::owner_read);
    CHECK(readObj(locked).mesh.numFaces() == 1);
}

TEST_CASE("obj: readObj and parseObj agree, errors from readObj name the path", "[io][obj]") {
    test::TempDir dir;
    const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    test::writeText(dir / "tri.obj", text);
    CHECK(toVector(readObj(dir / "tri.obj").mesh.faceIndices()) == std::vector<int32_t>{0, 1, 2});
    test::writeText(dir / "bad.obj", text + "f 1 2 5\n");
    CHECK_THROWS_WITH(readObj(dir / "bad.obj"), Catch::Contains((dir / "bad.obj").string() + ": line 5: "));
}

TEST_CASE("obj: formatObj writes float32 with 9 significant digits, groups as g", "[io][obj]") {
    Mesh::Data d;
    d.points = {{0.1f, -0.0f, 1e-40f}, {1.0f, 2.5f, -3e30f}, {0.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}};
    d.faceCounts = {3, 3};
    d.faceIndices = {0, 1, 2, 1, 3, 2};
    d.uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
    d.uvIndices = {0, 1, 2, 1, 1, 2};
    const Mesh mesh(std::move(d));
    const std::string text = formatObj(mesh, {{"top", {1}}, {"all", {0, 1}}});
    CHECK(text ==
          "# DeformKit OBJ: 4 vertices, 2 faces\n"
          "v 0.100000001 -0 9.9999461e-41\n"
          "v 1 2.5 -2.99999989e+30\n"
          "v 0 1 0\n"
          "v 1 1 0\n"
          "vt 0 0\n"
          "vt 1 0\n"
          "vt 0 1\n"
          "g all\n"
          "f 1/1 2/2 3/3\n"
          "g top all\n"
          "f 2/2 4/2 3/3\n");
    const std::string coarse = formatObj(mesh, {}, {.precision = 3});
    CHECK(coarse.find("v 0.1 -0 1e-40\n") != std::string::npos);
    CHECK(coarse.find("f 2/2 4/2 3/3\n") != std::string::npos);
}

TEST_CASE("obj: formatObj rejects what it cannot write", "[io][obj][errors]") {
    const Mesh grid = deformkit::geom::makeGrid({2, 2});
    CHECK_THROWS_WITH(formatObj(grid, {{"a", {0, 4}}}), Catch::Contains("group 'a'") &&
                                                            Catch::Contains("face index 4 is out of range") &&
                                                            Catch::Contains("[0, 4)"));
    CHECK_THROWS_AS(formatObj(grid, {{"two words", {0}}}), InvalidInput);
    CHECK_THROWS_AS(formatObj(grid, {{"", {0}}}), InvalidInput);
    CHECK_THROWS_AS(formatObj(grid, {{"#hash", {0}}}), InvalidInput);
    CHECK_THROWS_AS(formatObj(grid, {{"ends\\", {0}}}), InvalidInput);
    CHECK_THROWS_WITH(formatObj(grid, {}, {.precision = 0}), Catch::Contains("precision"));
    CHECK_THROWS_WITH(formatObj(Mesh()), Catch::Contains("the mesh has no faces"));
    test::TempDir dir;
    CHECK_THROWS_WITH(writeObj(dir / "named.obj", grid, {{"a b", {0}}}),
                      Catch::Contains((dir / "named.obj").string() + ": group 'a b': cannot be written"));
    CHECK_FALSE(fs::exists(dir / "named.obj"));
}

TEST_CASE("obj: write then read gives bit-identical meshes", "[io][obj]") {
    test::TempDir dir;
    using namespace deformkit::geom;
    SECTION("grid") {
        const Mesh grid = makeGrid({7, 5, 3.3f, 1.7f});
        const std::vector<FaceGroup> groups = {{"left", {0, 1, 2, 7, 8}}, {"rest", {3, 4, 5, 6, 9}}};
        checkIdentical(roundTrip(dir, grid, groups), grid, groups);
    }
    SECTION("sphere") {
        const Mesh sphere = makeSphere({0.37f, 24, 13});
        checkIdentical(roundTrip(dir, sphere), sphere, {});
    }
    SECTION("capped tube") {
        const Mesh tube = makeCappedTube({1.3f, 4.1f, 40, 30, 5});
        checkIdentical(roundTrip(dir, tube), tube, {});
    }
    SECTION("random n-gons with extreme values and overlapping groups") {
        for (uint32_t seed : {1u, 2u, 3u}) {
            const auto [mesh, groups] = randomMesh(seed);
            checkIdentical(roundTrip(dir, mesh, groups), mesh, groups);
        }
    }
    SECTION("no UVs, and faces outside any group") {
        const Mesh sphere = makeSphere({1.0f, 8, 4});
        Mesh::Data d;
        d.points.assign(sphere.points().begin(), sphere.points().end());
        d.faceCounts.assign(sphere.faceCounts().begin(), sphere.faceCounts().end());
        d.faceIndices.assign(sphere.faceIndices().begin(), sphere.faceIndices().end());
        const Mesh bare(std::move(d));
        const std::vector<FaceGroup> groups = {{"cap", {2, 3, 4}}, {"band", {10, 20}}};
        const ObjContent read = roundTrip(dir, bare, groups);
        CHECK_FALSE(read.mesh.hasUVs());
        checkIdentical(read, bare, groups);
    }
    std::vector<fs::path> left;
    for (const auto& entry : fs::directory_iterator(dir.path()))
        left.push_back(entry.path().filename());
    CHECK(left == std::vector<fs::path>{"round_trip.obj"});
}

TEST_CASE("obj: a failed write leaves the existing file intact and no temporary", "[io][obj][errors]") {
    test::TempDir dir;
    const fs::path path = dir / "mesh.obj";
    const std::string original = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    test::writeText(path, original);
    fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                    fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
    const Mesh grid = deformkit::geom::makeGrid({3, 3});
    const bool refused = test::runUnprivileged([&] {
        try {
            writeObj(path, grid);
        } catch (const IoError& e) {
            return std::string(e.what()).find("not writable") != std::string::npos;
        }
        return false;
    });
    CHECK(refused);
    fs::permissions(dir.path(), fs::perms::owner_all);
    CHECK(test::readText(path) == original);
    std::vector<fs::path> left;
    for (const auto& entry : fs::directory_iterator(dir.path()))
        left.push_back(entry.path().filename());
    CHECK(left == std::vector<fs::path>{"mesh.obj"});

    // Writable again: the file is replaced whole.
    writeObj(path, grid);
    CHECK(readObj(path).mesh.numFaces() == 9);
}

TEST_CASE("obj: polygons that visit a vertex twice are repaired, as exporters write them", "[io][obj]") {
    // Eight points: an outer square 1-4 and an inner one 5-8, with UVs equal to x, y.
    std::string points;
    for (const auto& [x, y] : std::vector<std::pair<double, double>>{
             {0, 0}, {4, 0}, {4, 4}, {0, 4}, {1, 1}, {1, 3}, {3, 3}, {3, 1}}) {
        points += "v " + std::to_string(x) + " " + std::to_string(y) + " 0\n";
        points += "vt " + std::to_string(x / 4) + " " + std::to_string(y / 4) + "\n";
    }
    const auto faces = [](const ObjContent& c) {
        std::vector<std::vector<int32_t>> out;
        for (int32_t f = 0; f < c.mesh.numFaces(); ++f) {
            const auto v = c.mesh.face(f);
            out.emplace_back(v.begin(), v.end());
        }
        return out;
    };
    using Faces = std::vector<std::vector<int32_t>>;
    // A line repeating its corners (box_longline.obj): one face.
    ObjContent c = parseObj(points + "f 1/1 2/2 3/3 4/4 1/1 2/2 3/3 4/4 1/1 2/2 3/3 4/4\n", "long.obj");
    CHECK(faces(c) == Faces{{0, 1, 2, 3}});
    CHECK((c.repairedFaces == 1 && c.firstRepairedLine == 17));
    // Repeats one after the other, and the last corner again at the end: dropped, UVs with their corners.
    c = parseObj(points + "f 1/1 2/2 2/2 3/3 4/4 1/1\n", "repeat.obj");
    CHECK(faces(c) == Faces{{0, 1, 2, 3}});
    const auto uvs = c.mesh.faceUVIndices(0);
    CHECK(std::vector<int32_t>(uvs.begin(), uvs.end()) == std::vector<int32_t>{0, 1, 2, 3});
    // A square with a square hole, joined by an edge walked both ways (concave_polygon.obj): the outline
    // and the hole's loop become faces; the bridge (two corners) is dropped.
    c = parseObj(points + "f 1 2 3 4 5 6 7 8 5 4\n", "hole.obj");
    Faces got = faces(c);
    std::sort(got.begin(), got.end());
    CHECK(got == Faces{{0, 1, 2, 3}, {4, 5, 6, 7}});
    CHECK(c.repairedFaces == 1);
    // A file without repeats reports none.
    CHECK(parseObj(points + "f 1 2 3 4\n", "plain.obj").repairedFaces == 0);
    // A long polygon (past the pair-by-pair check) visiting a vertex twice splits into its two loops.
    std::string ring;
    for (int i = 0; i < 40; ++i)
        ring +=
            "v " + std::to_string(std::cos(i * 0.157)) + " " + std::to_string(std::sin(i * 0.157)) + " 0\n";
    std::string face = "f";
    for (int i = 1; i <= 40; ++i)
        face += " " + std::to_string(i);
    c = parseObj(ring + face + " 20\n", "ring.obj");  // back to vertex 20 at the end: loops 20..40 and 1..20
    got = faces(c);
    std::sort(got.begin(), got.end());
    Faces want(2);
    for (int i = 0; i < 20; ++i)
        want[0].push_back(i);
    for (int i = 19; i < 40; ++i)
        want[1].push_back(i);
    std::sort(want.begin(), want.end());
    CHECK(c.repairedFaces == 1);
    REQUIRE(got.size() == 2);
    // Each loop as a cyclic sequence: rotated to start at its least vertex.
    for (auto& loop : got)
        std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
    CHECK(got == want);
}

TEST_CASE("obj: the OBJ files of another library's test suite (assimp-testmodels), when installed",
          "[io][obj][assimp]") {
    const std::filesystem::path folder = "/usr/share/assimp/models/OBJ";
    if (!std::filesystem::is_directory(folder)) {
        WARN("assimp-testmodels is not installed (scripts/setup.sh installs it): skipped");
        return;
    }
    // What a production reader reads, and what is truly broken (no faces, malformed numbers, UTF-16).
    const std::map<std::string, std::string> refused = {{"box_UTF16BE.obj", "is UTF-16 text"},
                                                        {"number_formats.obj", "malformed number"},
                                                        {"point_cloud.obj", "contains no faces"},
                                                        {"testline.obj", "contains no faces"},
                                                        {"testpoints.obj", "contains no faces"}};
    int read = 0;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.path().extension() != ".obj") continue;
        const std::string name = entry.path().filename().string();
        INFO(name);
        const auto expected = refused.find(name);
        if (expected == refused.end()) {
            const ObjContent c = readObj(entry.path());
            CHECK(c.mesh.numFaces() > 0);
            ++read;
            // regr01.obj mixes faces with texture coordinates and faces without (from line 83).
            if (name == "regr01.obj") {
                CHECK(c.facesWithoutUVs > 0);
                CHECK(c.firstLineWithoutUVs == 83);
                CHECK(c.facesWithoutUVs < c.mesh.numFaces());
            }
        } else {
            CHECK_THROWS_WITH(readObj(entry.path()), Catch::Contains(expected->second));
        }
    }
    CHECK(read == 17);  // 17 of the package's 22 OBJ files (5.2.5)
}

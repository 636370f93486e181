// deformkit: the standalone host. Exit codes: 0 success; 2 bad input or usage, with one line on
// stderr; 1 internal error.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>

#include <unistd.h>

#include "commands.h"
#include "deformkit/error.h"
#include "deformkit/version.h"
#include "eval_command.h"
#include "farm_command.h"
#include "ptex_command.h"
#include "slide_command.h"
#include "uvwarp_command.h"
#include "warp_command.h"

namespace {

// "x,y,z" -> vec3, for --view.
glm::vec3 parseVec3(const std::string& text) {
    glm::vec3 v;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%f,%f,%f%c", &v.x, &v.y, &v.z, &tail) != 3) {
        throw deformkit::InvalidInput(deformkit::formatError(
            "--view", "", "'" + text + "' is not a direction", "three numbers: x,y,z"));
    }
    return v;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace deformkit;
    CLI::App app{"DeformKit: production deformers (slide, warps, content-aware UV warp)", "deformkit"};
    app.set_version_flag("--version", std::string("deformkit ") + kVersionString);
    app.require_subcommand(1);

    std::string infoFile;
    auto* info =
        app.add_subcommand("info", "Describe a mesh (.obj), an image, or the tiles of a UDIM pattern");
    info->add_option("FILE", infoFile, "mesh, image, or pattern with <UDIM>, <UVTILE>, %(UDIM)d or _MAPID_")
        ->required();

    harness::PreviewCommand previewCommand;
    std::string previewMesh, previewTexture, previewOut, previewView;
    auto* preview =
        app.add_subcommand("preview", "Render a shaded, optionally textured view of a mesh to an image");
    preview->add_option("MESH", previewMesh, "mesh (.obj)")->required();
    preview->add_option("--texture", previewTexture, "image, or UDIM pattern such as albedo.<UDIM>.png");
    preview->add_option("--out", previewOut, "output image (.png)")->required();
    preview->add_option("--width", previewCommand.options.width, "pixels")->capture_default_str();
    preview->add_option("--height", previewCommand.options.height, "pixels")->capture_default_str();
    preview->add_option("--view", previewView, "camera direction x,y,z (y up); default -0.55,-0.45,-1");
    preview->add_flag("--edges", previewCommand.options.drawEdges, "draw polygon edges");
    std::string previewWeights, previewWeightsPtex;
    preview->add_option("--weights", previewWeights,
                        "show painted weights (JSON array, one per vertex) as colours");
    preview->add_option("--weights-ptex", previewWeightsPtex,
                        "show a Ptex map's per-vertex values as colours");
    preview->add_option("--weights-channel", previewCommand.weightsChannel, "the Ptex map's channel")
        ->capture_default_str();

    harness::DemoCommand demoCommand;
    std::string demoOut = demoCommand.outDir.string();
    auto* demo = app.add_subcommand("demo", "Generate the demo assets and previews into a folder");
    demo->add_option("--out", demoOut, "output folder")->capture_default_str();
    demo->add_option("--resolution", demoCommand.resolution, "texels per UDIM tile side")
        ->capture_default_str();

    harness::EvalCommand evalCommand;
    std::string evalScene, evalFrames, evalOut = evalCommand.outDir.string();
    auto* evalApp = app.add_subcommand(
        "eval", "Evaluate a scene's deformer stacks frame by frame and write one OBJ per object and frame");
    evalApp->add_option("SCENE", evalScene, "scene (.json, docs/scene.md)")->required();
    evalApp->add_option("--frames", evalFrames,
                        "frames: 1-24, or a list such as 1-10,15; default: the scene's");
    evalApp
        ->add_option("--out", evalOut,
                     "output folder: <object>.<frame>.obj and .png, <object>.contact.png, <object>.mp4")
        ->capture_default_str();
    bool evalNoPreviews = false;
    evalApp->add_flag("--no-previews", evalNoPreviews,
                      "write only the OBJs (no PNG previews, contact sheets or movies)");
    evalApp->add_option("--preview-width", evalCommand.previewWidth, "preview width in pixels")
        ->capture_default_str();
    evalApp->add_option("--preview-height", evalCommand.previewHeight, "preview height in pixels")
        ->capture_default_str();
    evalApp->add_flag("--movie", evalCommand.movie,
                      "also encode <object>.mp4 from the previews when ffmpeg is on PATH");
    evalApp->add_option("--fps", evalCommand.movieFrameRate, "movie frame rate")->capture_default_str();

    harness::FarmPlanCommand farmPlanCommand;
    harness::FarmRunCommand farmRunCommand;
    harness::FarmSubmitCommand farmSubmitCommand;
    bool farmSlurm = false;
    std::string farmScene, farmFrames, farmOut, farmPlanFile, farmRunPlan, farmSubmitPlan, farmSbatchArgs;
    auto* farmApp = app.add_subcommand(
        "farm",
        "Cut a scene's evaluation into render-farm tasks, run one task, or submit them (docs/farm.md)");
    farmApp->require_subcommand(1);
    auto* farmPlanApp = farmApp->add_subcommand(
        "plan", "Write a plan: tasks of at most --chunk frames with their output files");
    farmPlanApp->add_option("SCENE", farmScene, "scene (.json, docs/scene.md)")->required();
    farmPlanApp->add_option("--frames", farmFrames,
                            "frames: 1-240, or a list such as 1-10,15; default: the scene's");
    farmPlanApp->add_option("--chunk", farmPlanCommand.chunk, "frames per task at most")
        ->capture_default_str();
    farmPlanApp
        ->add_option("--tiles-per-task", farmPlanCommand.tilesPerTask,
                     "UDIM tiles per UV-warp task at most (scenes with a uvwarp stage)")
        ->capture_default_str();
    farmPlanApp->add_option("--out", farmOut, "output folder of the tasks: <object>.<frame 4 digits>.obj")
        ->required();
    farmPlanApp->add_option("--plan", farmPlanFile, "plan file to write; default: <out>/farm_plan.json");
    auto* farmRunApp = farmApp->add_subcommand(
        "run",
        "Run one task of a plan, skipping frames already written; JSON lines on stdout. Exit 0 done, "
        "2 bad input, 1 worth a retry");
    farmRunApp->add_option("PLAN", farmRunPlan, "plan (.json) from deformkit farm plan")->required();
    farmRunApp->add_option("--task", farmRunCommand.task, "task index, from 0")->required();
    auto* farmSubmitApp = farmApp->add_subcommand(
        "submit", "Submit a plan as a job array, one element per task; prints the job id");
    farmSubmitApp->add_flag("--slurm", farmSlurm, "submit with Slurm's sbatch (the one scheduler supported)")
        ->required();
    farmSubmitApp->add_option("PLAN", farmSubmitPlan, "plan (.json) from deformkit farm plan")->required();
    farmSubmitApp->add_option("--sbatch-args", farmSbatchArgs,
                              "extra sbatch options, e.g. \"--partition=batch --time=1:00:00\"");

    harness::WarpImageCommand warpCommand;
    std::string warpImage, warpLines, warpOut, warpVariant = "original", warpInterp = "bilinear";
    auto* warpImageApp =
        app.add_subcommand("warp", "Warp an image with Beier-Neely segment pairs (inverse mapping)");
    warpImageApp->add_option("IMAGE", warpImage, "source image")->required();
    warpImageApp->add_option("--lines", warpLines, "segment pairs, JSON (docs/warps/beier_neely.md)")
        ->required();
    warpImageApp->add_option("--out", warpOut, "output image, same size and channels")->required();
    warpImageApp->add_option("--variant", warpVariant, "original or global (no fold-over, paper 5.2)")
        ->check(CLI::IsMember({"original", "global"}))
        ->capture_default_str();
    warpImageApp->add_option("--interp", warpInterp, "bilinear or bicubic")
        ->check(CLI::IsMember({"bilinear", "bicubic"}))
        ->capture_default_str();

    harness::SlideCommand slideCommand;
    std::string slideMesh, slideOut, slideFrom, slideTo, slideFalloff = "smooth", slideWeights;
    std::string slideRegion = "euclidean", slideSurface = "cage";
    auto* slideApp = app.add_subcommand("slide", "Slide vertices over the surface around a handle (Pinskiy)");
    slideApp->add_option("MESH", slideMesh, "mesh (.obj)")->required();
    slideApp->add_option("--handle", slideCommand.handle.vertex, "handle vertex index (0-based)")->required();
    slideApp->add_option("--from", slideFrom, "start locator x,y,z")->required();
    slideApp->add_option("--to", slideTo, "end locator x,y,z: the handle region slides by to - from")
        ->required();
    slideApp->add_option("--radius", slideCommand.handle.radius, "support radius, scene units")->required();
    slideApp->add_option("--out", slideOut, "output mesh (.obj), UVs and groups kept")->required();
    slideApp
        ->add_option("--falloff", slideFalloff,
                     "smooth, linear, or ramp samples v0,v1,... over distance/radius")
        ->capture_default_str();
    slideApp->add_option("--weights", slideWeights, "painted weights: a JSON array of one number per vertex");
    std::string slideWeightsPtex;
    slideApp->add_option("--weights-ptex", slideWeightsPtex,
                         "painted weights from a Ptex map of the mesh (per-vertex values)");
    slideApp->add_option("--weights-channel", slideCommand.weightsChannel, "the Ptex map's channel")
        ->capture_default_str();
    slideApp->add_option("--envelope", slideCommand.envelope, "scales every slide")->capture_default_str();
    slideApp->add_option("--region", slideRegion, "euclidean (3D distance) or geodesic (over the surface)")
        ->check(CLI::IsMember({"euclidean", "geodesic"}))
        ->capture_default_str();
    slideApp
        ->add_option("--surface", slideSurface, "cage (the mesh) or limit (its Catmull-Clark limit surface)")
        ->check(CLI::IsMember({"cage", "limit"}))
        ->capture_default_str();
    slideApp
        ->add_option("--max-walk", slideCommand.options.maxWalkTriangles,
                     "triangles one vertex may cross before it stops")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();

    harness::UvWarpCommand uvwarpCommand;
    std::string uvFrames, uvTiles, uvMask, uvOrientation, uvTexture, uvBake, uvLog, uvFilter = "bilinear";
    std::string uvRest, uvDeformed, uvRigidity, uvOut;
    uvwarp::SolverOptions& uvSolver = uvwarpCommand.options.solver;
    auto* uvwarpApp = app.add_subcommand(
        "uvwarp",
        "Content-aware UV warp over a shot: per UDIM tile and frame a redirect map (and a baked texture)");
    uvwarpApp->add_option("--rest", uvRest, "rest mesh with UVs (.obj)")->required();
    uvwarpApp
        ->add_option("--deformed", uvDeformed, "deformed frames, e.g. 'anim.####.obj' (# per digit) or %04d")
        ->required();
    uvwarpApp->add_option("--frames", uvFrames, "frames: 1-24, or a list such as 1-10,15")->required();
    uvwarpApp->add_option("--rigidity", uvRigidity, "rigidity maps, e.g. 'rig.<UDIM>.exr' (1 = rigid)")
        ->required();
    uvwarpApp->add_option("--mask", uvMask,
                          "warp masks, e.g. 'mask.<UDIM>.exr' (>= 0.5 may warp); default: from the UVs");
    uvwarpApp->add_option("--orientation", uvOrientation,
                          "orientation-preservation maps, e.g. 'orient.<UDIM>.exr' (in [0, 1], scales "
                          "--orientation-preservation per texel)");
    auto* uvTextureOption = uvwarpApp->add_option("--texture", uvTexture,
                                                  "texture to bake, e.g. 'col.<UDIM>.exr' (needs --bake)");
    uvwarpApp
        ->add_option("--out", uvOut,
                     "redirect maps, e.g. 'out/redirect.<UDIM>.####.exr' (2-channel float EXR)")
        ->required();
    auto* uvBakeOption = uvwarpApp->add_option(
        "--bake", uvBake, "baked textures, e.g. 'out/col.<UDIM>.####.exr' (needs --texture)");
    uvTextureOption->needs(uvBakeOption);
    uvBakeOption->needs(uvTextureOption);
    uvwarpApp->add_option("--tiles", uvTiles,
                          "UDIM tiles, e.g. 1001,1002; default: every tile of the rest UVs");
    uvwarpApp
        ->add_option("--resolution", uvwarpCommand.resolution,
                     "grid cells per side, a power of two; 0: the rigidity map's size")
        ->capture_default_str();
    uvwarpApp->add_option("--log", uvLog, "JSON-lines log, appended: one line per tile and frame");
    uvwarpApp->add_option("--filter", uvFilter, "bake filter: bilinear or bicubic")
        ->check(CLI::IsMember({"bilinear", "bicubic"}))
        ->capture_default_str();
    uvwarpApp->add_option("--iterations", uvSolver.iterations, "PBD iterations per frame")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    uvwarpApp->add_option("--levels", uvSolver.levels, "hierarchy levels; 0: automatic")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    uvwarpApp
        ->add_option("--sweeps", uvSolver.sweepsPerLevel,
                     "constraint sweeps per iteration and level, finest first")
        ->delimiter(',')
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    uvwarpApp->add_option("--orientation-preservation", uvSolver.orientationPreservation, "in [0, 1]")
        ->check(CLI::Range(0.0f, 1.0f))
        ->capture_default_str();
    uvwarpApp->add_option("--smoothing", uvSolver.smoothing, "smoothing of rigid points, in [0, 1]")
        ->check(CLI::Range(0.0f, 1.0f))
        ->capture_default_str();
    uvwarpApp->add_option("--damping", uvSolver.damping, "velocity damping, in [0, 1]")
        ->check(CLI::Range(0.0f, 1.0f))
        ->capture_default_str();
    uvwarpApp->add_option("--coarse-stiffness", uvSolver.coarseStiffness, "per coarser level, in (0, 1]")
        ->check(CLI::Range(1e-6f, 1.0f))
        ->capture_default_str();
    uvwarpApp
        ->add_option("--border-width", uvwarpCommand.options.derivedMask.borderWidth,
                     "texels of chart border kept fixed by a derived mask")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();

    auto* ptexApp = app.add_subcommand("ptex", "Ptex files: describe, per-vertex values, UDIM conversions");
    ptexApp->require_subcommand(1);
    std::string ptexInfoFile;
    auto* ptexInfoApp =
        ptexApp->add_subcommand("info", "Header, faces and resolutions, metadata of a Ptex file");
    ptexInfoApp->add_option("FILE", ptexInfoFile, "Ptex file (.ptx)")->required();
    harness::PtexToVertexCommand ptexToVertex;
    std::string ptexToVertexFile, ptexToVertexMesh, ptexToVertexOut;
    auto* ptexToVertexApp =
        ptexApp->add_subcommand("to-vertex", "Per-vertex values of a Ptex map as a JSON weights file");
    ptexToVertexApp->add_option("FILE", ptexToVertexFile, "Ptex file painted on MESH")->required();
    ptexToVertexApp->add_option("MESH", ptexToVertexMesh, "mesh (.obj)")->required();
    ptexToVertexApp->add_option("--out", ptexToVertexOut, "weights file (.json)")->required();
    ptexToVertexApp->add_option("--channel", ptexToVertex.channel, "channel")->capture_default_str();
    harness::PtexToUdimCommand ptexToUdim;
    std::string ptexToUdimFile, ptexToUdimMesh, ptexToUdimTiles;
    auto* ptexToUdimApp =
        ptexApp->add_subcommand("to-udim", "Render a Ptex map into UDIM tile images through the mesh's UVs");
    ptexToUdimApp->add_option("FILE", ptexToUdimFile, "Ptex file painted on MESH")->required();
    ptexToUdimApp->add_option("MESH", ptexToUdimMesh, "mesh (.obj) with UVs")->required();
    ptexToUdimApp->add_option("--out", ptexToUdim.out, "UDIM pattern, such as 'map.<UDIM>.exr'")->required();
    ptexToUdimApp->add_option("--resolution", ptexToUdim.resolution, "pixels per tile side")
        ->capture_default_str();
    ptexToUdimApp->add_option("--tiles", ptexToUdimTiles, "tiles to write (default: every tile of the mesh)");
    harness::PtexFromUdimCommand ptexFromUdim;
    std::string ptexFromUdimMesh, ptexFromUdimOut, ptexFaceRes = "auto", ptexType = "float";
    auto* ptexFromUdimApp = ptexApp->add_subcommand(
        "from-udim", "Sample UDIM tile images into a Ptex file through the mesh's UVs");
    ptexFromUdimApp->add_option("PATTERN", ptexFromUdim.pattern, "UDIM pattern, such as 'map.<UDIM>.exr'")
        ->required();
    ptexFromUdimApp->add_option("MESH", ptexFromUdimMesh, "mesh (.obj) with UVs")->required();
    ptexFromUdimApp->add_option("--out", ptexFromUdimOut, "Ptex file (.ptx)")->required();
    ptexFromUdimApp->add_option("--face-res", ptexFaceRes, "texels per face side: auto or a power of two")
        ->capture_default_str();
    ptexFromUdimApp->add_option("--type", ptexType, "u8, u16, half or float")->capture_default_str();
    harness::PtexFromVertexCommand ptexFromVertex;
    std::string ptexFromVertexWeights, ptexFromVertexMesh, ptexFromVertexOut, ptexVertexFaceRes = "16",
                                                                              ptexVertexType = "float";
    auto* ptexFromVertexApp = ptexApp->add_subcommand(
        "from-vertex", "Bake per-vertex weights (a JSON weights file) into a Ptex file");
    ptexFromVertexApp->add_option("WEIGHTS", ptexFromVertexWeights, "weights file (.json), one per vertex")
        ->required();
    ptexFromVertexApp->add_option("MESH", ptexFromVertexMesh, "mesh (.obj)")->required();
    ptexFromVertexApp->add_option("--out", ptexFromVertexOut, "Ptex file (.ptx)")->required();
    ptexFromVertexApp->add_option("--face-res", ptexVertexFaceRes, "texels per face side, a power of two")
        ->capture_default_str();
    ptexFromVertexApp->add_option("--type", ptexVertexType, "u8, u16, half or float")->capture_default_str();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // Help and version print and exit 0; a usage error is one line on stderr and exit code 2.
        if (e.get_exit_code() == 0) return app.exit(e);
        std::cerr << "deformkit: usage error: " << e.what() << " (see deformkit --help)\n";
        return 2;
    }

    try {
        if (*info) {
            harness::describe(infoFile, std::cout);
        } else if (*preview) {
            previewCommand.mesh = previewMesh;
            previewCommand.out = previewOut;
            if (!previewTexture.empty()) previewCommand.texture = previewTexture;
            if (!previewView.empty()) previewCommand.options.viewDirection = parseVec3(previewView);
            if (!previewWeights.empty()) previewCommand.weights = previewWeights;
            if (!previewWeightsPtex.empty()) previewCommand.weightsPtex = previewWeightsPtex;
            harness::preview(previewCommand);
            std::cout << "wrote " << previewOut << "\n";
        } else if (*warpImageApp) {
            warpCommand.image = warpImage;
            warpCommand.lines = warpLines;
            warpCommand.out = warpOut;
            warpCommand.variant =
                warpVariant == "global" ? warp::BeierNeelyVariant::Global : warp::BeierNeelyVariant::Original;
            warpCommand.interpolation =
                warpInterp == "bicubic" ? io::SampleFilter::Bicubic : io::SampleFilter::Bilinear;
            harness::warpImageCommand(warpCommand);
            std::cout << "wrote " << warpOut << "\n";
        } else if (*slideApp) {
            slideCommand.mesh = slideMesh;
            slideCommand.out = slideOut;
            slideCommand.from = harness::parsePoint(slideFrom, "--from");
            slideCommand.to = harness::parsePoint(slideTo, "--to");
            slideCommand.falloff = harness::parseFalloff(slideFalloff);
            if (!slideWeights.empty()) slideCommand.weights = slideWeights;
            if (!slideWeightsPtex.empty()) slideCommand.weightsPtex = slideWeightsPtex;
            slideCommand.handle.region =
                slideRegion == "geodesic" ? slide::RegionMetric::Geodesic : slide::RegionMetric::Euclidean;
            slideCommand.options.surface =
                slideSurface == "limit" ? slide::SurfaceMode::Limit : slide::SurfaceMode::Cage;
            const slide::SlideResult result = harness::slideCommand(slideCommand);
            std::cout << harness::slideSummary(slideOut, result) << "\n";
        } else if (*uvwarpApp) {
            uvwarpCommand.rest = uvRest;
            uvwarpCommand.deformed = uvDeformed;
            uvwarpCommand.frames = harness::parseFrames(uvFrames);
            uvwarpCommand.rigidity = uvRigidity;
            uvwarpCommand.out = uvOut;
            if (!uvMask.empty()) uvwarpCommand.mask = uvMask;
            if (!uvOrientation.empty()) uvwarpCommand.orientation = uvOrientation;
            if (!uvTexture.empty()) uvwarpCommand.texture = uvTexture;
            if (!uvBake.empty()) uvwarpCommand.bake = uvBake;
            if (!uvTiles.empty()) uvwarpCommand.tiles = harness::parseTiles(uvTiles);
            if (!uvLog.empty()) uvwarpCommand.log = uvLog;
            uvwarpCommand.filter =
                uvFilter == "bicubic" ? io::SampleFilter::Bicubic : io::SampleFilter::Bilinear;
            // The progress bar redraws one line in place: only for a person watching a terminal.
            const harness::UvWarpReport report =
                harness::uvwarpCommand(uvwarpCommand, ::isatty(STDERR_FILENO) ? &std::cerr : nullptr);
            for (const std::string& line : harness::uvwarpSummary(report))
                std::cout << "uvwarp: " << line << "\n";
        } else if (*evalApp) {
            evalCommand.scene = evalScene;
            evalCommand.outDir = evalOut;
            if (!evalFrames.empty()) evalCommand.frames = harness::parseFrames(evalFrames);
            evalCommand.previews = !evalNoPreviews;
            const harness::EvalReport report = harness::evalCommand(evalCommand, &std::cout);
            std::cout << "eval: wrote " << report.files.size() << " files to " << evalOut << "/\n";
            for (const std::string& note : report.notes)
                std::cout << "eval: " << note << "\n";
        } else if (*farmPlanApp) {
            farmPlanCommand.scene = farmScene;
            farmPlanCommand.outDir = farmOut;
            farmPlanCommand.plan = farmPlanFile;
            if (!farmFrames.empty()) farmPlanCommand.frames = harness::parseFrames(farmFrames);
            const harness::FarmPlan plan = harness::farmPlanCommand(farmPlanCommand);
            std::cout << "farm: wrote " << harness::farmPlanPath(farmPlanCommand).string() << ": "
                      << plan.tasks.size() << (plan.tasks.size() == 1 ? " task" : " tasks") << "\n";
        } else if (*farmRunApp || *farmSubmitApp) {
            // Exit codes a farm manager acts on: 2 bad input (no retry), 1 anything else (worth a retry).
            try {
                if (*farmRunApp) {
                    farmRunCommand.plan = farmRunPlan;
                    (void)harness::farmRunCommand(farmRunCommand, &std::cout);
                } else {
                    farmSubmitCommand.plan = farmSubmitPlan;
                    farmSubmitCommand.sbatchArgs = harness::splitArguments(farmSbatchArgs, "--sbatch-args");
                    std::cout << harness::farmSubmitCommand(farmSubmitCommand) << "\n";
                }
            } catch (const std::exception& e) {
                std::cerr << "deformkit: error: " << e.what() << "\n";
                return harness::farmExitCode(e);
            }
        } else if (*ptexInfoApp) {
            harness::ptexInfo(ptexInfoFile, std::cout);
        } else if (*ptexToVertexApp) {
            ptexToVertex.ptex = ptexToVertexFile;
            ptexToVertex.mesh = ptexToVertexMesh;
            ptexToVertex.out = ptexToVertexOut;
            const size_t count = harness::ptexToVertexCommand(ptexToVertex);
            std::cout << "wrote " << ptexToVertexOut << ": " << count << " vertex values\n";
        } else if (*ptexToUdimApp) {
            ptexToUdim.ptex = ptexToUdimFile;
            ptexToUdim.mesh = ptexToUdimMesh;
            if (!ptexToUdimTiles.empty()) ptexToUdim.tiles = harness::parseTiles(ptexToUdimTiles);
            for (const auto& f : harness::ptexToUdimCommand(ptexToUdim))
                std::cout << "wrote " << f.string() << "\n";
        } else if (*ptexFromUdimApp) {
            ptexFromUdim.mesh = ptexFromUdimMesh;
            ptexFromUdim.out = ptexFromUdimOut;
            ptexFromUdim.faceLog2 = harness::parseFaceResolution(ptexFaceRes);
            ptexFromUdim.type = harness::parsePtexType(ptexType);
            harness::ptexFromUdimCommand(ptexFromUdim);
            std::cout << "wrote " << ptexFromUdimOut << "\n";
        } else if (*ptexFromVertexApp) {
            ptexFromVertex.weights = ptexFromVertexWeights;
            ptexFromVertex.mesh = ptexFromVertexMesh;
            ptexFromVertex.out = ptexFromVertexOut;
            ptexFromVertex.faceLog2 = harness::parseFaceResolution(ptexVertexFaceRes);
            ptexFromVertex.type = harness::parsePtexType(ptexVertexType);
            harness::ptexFromVertexCommand(ptexFromVertex);
            std::cout << "wrote " << ptexFromVertexOut << "\n";
        } else if (*demo) {
            demoCommand.outDir = demoOut;
            const auto files = harness::demo(demoCommand);
            std::cout << "demo: wrote " << files.size() << " files to " << demoCommand.outDir.string()
                      << "/\n";
            for (const auto& f : files)
                std::cout << "  " << f.string() << "\n";
        }
    } catch (const Error& e) {
        std::cerr << "deformkit: error: " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "deformkit: internal error: " << e.what() << "\n";
        return 1;
    }
    return 0;
}

// MLOD on LibTorch (built with MLIDAR_WITH_DETECT): stage 1's targets decode back to the boxes, the losses of
// eq 6.15-6.17, deterministic and exactly resumable training, the model folder's rules, and a short end-to-end run
// that must find isolated cars in held-out frames.
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <numeric>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/core/heap_settings.hpp"
#include "mlidar/detect/anchor_targets.hpp"
#include "mlidar/detect/box_coding.hpp"
#include "mlidar/detect/net/detector.hpp"
#include "mlidar/detect/net/stage1.hpp"
#include "mlidar/detect/net/stage2.hpp"
#include "mlidar/eval/box_iou.hpp"
#include "mlidar/eval/detection_ap.hpp"
#include "mlidar/sim/detection_dataset.hpp"
#include "mlidar/sim/rig.hpp"
#include "test_support.hpp"

namespace mlidar::detect {
namespace {

namespace fs = std::filesystem;

DetectConfig small_config() {
  DetectConfig config;
  config.grid = {-12.8, 12.8, -12.8, 12.8, -3.0, 3.0, 0.4};  // 64 x 64 pillars
  config.channels = 8;
  config.threads = 1;
  return config;
}

/// Points on a box's faces (a 5 x 5 grid on each vertical face): what a LiDAR would see of it, roughly.
std::vector<Vec3> points_on(const io::Box3D& box) {
  std::vector<Vec3> points;
  for (int i = 0; i < 5; ++i) {
    for (int k = 0; k < 5; ++k) {
      const double a = -0.45 + 0.225 * i, z = -0.45 + 0.225 * k;
      for (const Vec3& c : {Vec3(a, -0.5, z), Vec3(a, 0.5, z), Vec3(-0.5, a, z), Vec3(0.5, a, z)}) points.push_back(from_canonical(c, box));
    }
  }
  return points;
}

TEST(MlodStage1, PerfectHeadOutputsDecodeBackToTheBoxes) {
  const DetectConfig config = small_config();
  const std::vector<io::Box3D> boxes = {{Vec3(5.0, 3.0, 0.0), 4.3, 1.8, 1.5, 0.4},
                                        {Vec3(-6.0, -2.0, 0.0), 3.8, 1.7, 1.6, 2.9},  // heading beyond a half turn
                                        {Vec3(1.0, -8.0, 0.0), 4.6, 1.9, 1.7, -1.4}};
  std::vector<Vec3> points;
  for (const io::Box3D& box : boxes) {
    const std::vector<Vec3> on = points_on(box);
    points.insert(points.end(), on.begin(), on.end());
  }
  const net::Stage1Targets targets = net::stage1_targets(boxes, points, config);
  ASSERT_GE(targets.positives, 3);
  // The head a perfect network would give: the labels as large logits, the residuals and directions as targets.
  const long n = targets.label.size(0);
  const torch::Tensor logits = torch::where(targets.label.eq(1), torch::full({n}, 12.0), torch::full({n}, -12.0)).unsqueeze(0);
  const torch::Tensor direction = torch::one_hot(targets.direction, 2).to(torch::kFloat32).mul(24.0).sub(12.0).unsqueeze(0);
  const std::vector<torch::Tensor> output = {logits, targets.residual.unsqueeze(0), direction};
  const std::vector<net::Proposal> decoded = net::decode_stage1(output, 0, config, 0.5);
  ASSERT_EQ(decoded.size(), boxes.size());  // NMS leaves one per box
  for (const io::Box3D& box : boxes) {
    double best = 0.0;
    const net::Proposal* match = nullptr;
    for (const net::Proposal& p : decoded) {
      if (eval::iou_3d(p.box, box) > best) best = eval::iou_3d(p.box, box), match = &p;
    }
    ASSERT_NE(match, nullptr);
    EXPECT_GT(best, 0.999);
    EXPECT_NEAR(std::remainder(match->box.yaw - box.yaw, 2.0 * std::numbers::pi), 0.0, 1e-5);  // the direction bin too
  }
  // Its loss is (almost) nothing; a head of zeros pays for every positive.
  const net::Stage1Loss perfect = net::stage1_loss(output, 0, targets, config.stage1);
  EXPECT_LT(perfect.total.item<double>(), 1e-3);
  const std::vector<torch::Tensor> zeros = {torch::zeros_like(logits), torch::zeros_like(output[1]), torch::zeros_like(direction)};
  EXPECT_GT(net::stage1_loss(zeros, 0, targets, config.stage1).total.item<double>(), 0.5);
}

TEST(MlodStage1, AnchorsOfABoxNoLidarSeesAreIgnoredNotBackground) {
  const DetectConfig config = small_config();
  const std::vector<io::Box3D> boxes = {{Vec3(5.0, 3.0, 0.0), 4.3, 1.8, 1.5, 0.0}};
  const net::Stage1Targets seen = net::stage1_targets(boxes, points_on(boxes[0]), config);
  const net::Stage1Targets unseen = net::stage1_targets(boxes, std::vector<Vec3>{}, config);
  EXPECT_GT(seen.positives, 0);
  EXPECT_EQ(unseen.positives, 0);
  EXPECT_EQ(unseen.label.eq(-1).sum().item<long>(), seen.label.ne(0).sum().item<long>());
}

TEST(MlodStage2, InputIsTheProposalsPointsInItsCanonicalFrame) {
  DetectConfig config = small_config();
  config.stage2.points = 32;
  const io::Box3D box{Vec3(8.0, -3.0, 0.0), 4.0, 2.0, 1.5, 0.6};
  LidarPoints cloud;
  cloud.points = points_on(box);
  cloud.points.push_back(Vec3(40.0, 40.0, 0.0));  // far outside: left out
  for (std::size_t i = 0; i < cloud.points.size(); ++i) cloud.uncertainty.push_back(0.001 * (1.0 + static_cast<double>(i % 4)));
  const net::Proposal proposal{box, 0.8, 1.4};
  const net::Stage2Input input = net::stage2_input(cloud, std::span(&proposal, 1), config);
  ASSERT_EQ(input.points.sizes(), (std::vector<long>{1, net::kPointFeatures, 32}));
  const torch::Tensor xyz = input.points[0].narrow(0, 0, 3);
  EXPECT_LE(xyz.abs().max().item<double>(), 0.5 + 1e-6);  // every point on the box: inside [-1/2, 1/2]^3 (eq 6.12)
  EXPECT_NEAR(input.points[0][3].max().item<double>(), std::log(0.004), 1e-5);
  EXPECT_NEAR(input.max_uncertainty[0], 0.004, 1e-12);
  EXPECT_NEAR(input.proposals[0][0].item<double>(), 0.8, 1e-6);
}

TEST(MlodStage2, LossFollowsEq615To617) {
  Stage2Config config;
  // Two proposals on one box: a positive (IoU 0.8) and a negative far away.
  const io::Box3D truth{Vec3(10.0, 0.0, 0.0), 4.0, 2.0, 1.5, 0.0};
  std::vector<net::Proposal> proposals = {{io::Box3D{Vec3(10.2, 0.1, 0.0), 4.0, 2.0, 1.5, 0.05}, 0.9, 2.0},
                                          {io::Box3D{Vec3(30.0, 5.0, 0.0), 4.0, 2.0, 1.5, 0.0}, 0.4, -0.4}};
  const net::Stage2Targets targets = net::stage2_targets(proposals, std::span(&truth, 1), config);
  ASSERT_EQ(targets.positives, 1);
  EXPECT_EQ(targets.label[1].item<float>(), 0.0f);
  const Residual u_star = encode(truth, proposals[0].box);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(targets.residual[0][k].item<double>(), u_star[static_cast<std::size_t>(k)], 1e-6);
  net::Stage2Input input;
  input.max_uncertainty = {0.0004, 3.0};  // below the clamp's floor 1e-3: f = 1e-3
  const torch::Tensor u = torch::tensor({0.1f, -0.2f, 0.05f, 0.0f, 0.1f, 0.0f, 0.3f, 0.9f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f}).reshape({2, 8});
  const torch::Tensor logits = torch::tensor({1.0f, -1.0f});
  const net::Stage2Loss loss = net::stage2_loss({logits, u}, targets, input, config);
  // eq 6.16 by hand: exp(1 - 1e-3) times the norm of u' (u without its cosine) of the one positive.
  const double norm = std::sqrt(0.01 + 0.04 + 0.0025 + 0.01 + 0.09);
  EXPECT_NEAR(loss.uncertainty.item<double>(), std::exp(1.0 - 1e-3) * norm, 1e-5);
  // eq 6.17: L_reg + eta L_cls + lambda L_uct.
  EXPECT_NEAR(loss.total.item<double>(),
              loss.regression.item<double>() + 2.0 * loss.classification.item<double>() + 0.005 * loss.uncertainty.item<double>(), 1e-6);
  // Focal loss by hand for both (alpha 0.25 / 0.75, gamma 2).
  const double p0 = 1.0 / (1.0 + std::exp(-1.0)), p1 = 1.0 / (1.0 + std::exp(1.0));
  const double focal = 0.25 * std::pow(1 - p0, 2) * -std::log(p0) + 0.75 * std::pow(p1, 2) * -std::log(1 - p1);
  EXPECT_NEAR(loss.classification.item<double>(), focal, 1e-6);
}

fs::path cars_dataset(const fs::path& folder, int frames, sim::DetectionSplit split) {
  sim::DetectionSpec spec;
  spec.rig = sim::load_rig("lyft");
  spec.frames = frames;
  spec.seed = 11;
  spec.split = split;
  spec.layout = sim::DetectionLayout::kCars;
  sim::write_detection_dataset(spec, folder);
  return folder;
}

std::string log_text(const fs::path& model) { return test::read_text(model / "train_log.jsonl"); }

/// One logged term of every line of the log, in order.
std::vector<double> logged_values(const fs::path& model, const std::string& term) {
  std::vector<double> values;
  std::istringstream lines(log_text(model));
  for (std::string line; std::getline(lines, line);) {
    const auto at = line.find("\"" + term + "\":");
    if (at != std::string::npos) values.push_back(std::stod(line.substr(at + term.size() + 3)));
  }
  return values;
}

/// The losses of the log's lines (the seconds differ between runs).
std::vector<double> logged_losses(const fs::path& model) { return logged_values(model, "loss"); }

TEST(MlodTraining, IsDeterministicForASeedAndResumesExactly) {
  const fs::path dir = test::scratch_dir();
  const fs::path data = cars_dataset(dir / "data", 4, sim::DetectionSplit::kTrain);
  TrainRequest request;
  request.data = data;
  request.config = small_config();
  request.config.stage1.epochs = 5;  // 20 steps over 4 frames
  request.config.stage1.checkpoint_every = 3;
  request.stage = 1;
  request.out = dir / "a";
  train_detector(request);
  request.out = dir / "b";
  train_detector(request);
  const std::vector<double> a = logged_losses(dir / "a");
  ASSERT_EQ(a.size(), 2U);  // steps 10 and 20
  EXPECT_EQ(a, logged_losses(dir / "b"));
  // Interrupted at step 14 (a checkpoint at 10: every 3 steps rounded up to the log's 10), then resumed: the same
  // losses as without a break.
  request.out = dir / "c";
  EXPECT_THROW(train_detector(request, [](const TrainProgress& p) {
                 if (p.step == 14) throw std::runtime_error("interrupted");
               }),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "c" / "model.json"));
  EXPECT_THROW(train_detector(request), UsageError);  // a training is there: --resume or another folder
  request.resume = true;
  train_detector(request);
  EXPECT_EQ(logged_losses(dir / "c"), a);
  EXPECT_TRUE(fs::exists(dir / "c" / "loss.svg"));
  // Stage 1 saw perturbed frames (stage1.uncertain_share 0.6 by default): the log's mean alpha is not 0 on every line.
  const std::vector<double> alphas = logged_values(dir / "a", "alpha");
  EXPECT_GT(std::accumulate(alphas.begin(), alphas.end(), 0.0), 0.0);
  // Resuming with another configuration is refused with the reason.
  request.config.stage1.learning_rate *= 2.0;
  try {
    train_detector(request);
    ADD_FAILURE() << "a training of another configuration was resumed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another configuration"), std::string::npos) << e.what();
  }
}

TEST(MlodTraining, NeverWritesIntoAFolderOfOtherFiles) {
  const fs::path dir = test::scratch_dir();
  const fs::path data = cars_dataset(dir / "data", 1, sim::DetectionSplit::kTrain);
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine" / "notes.txt") << "mine";
  TrainRequest request;
  request.data = data;
  request.config = small_config();
  request.out = dir / "mine";
  EXPECT_THROW(train_detector(request), UsageError);
  EXPECT_EQ(test::read_text(dir / "mine" / "notes.txt"), "mine");
  request.out = dir / "empty";
  request.stage = 2;
  EXPECT_THROW(train_detector(request), UsageError);  // no stage 1 to refine
  request.out = data / "model";
  request.stage = 0;
  EXPECT_THROW(train_detector(request), UsageError);  // never inside the dataset
}

double ap3d_loose_hard(const fs::path& test_data, const Detector& detector) {
  const DetectionDataset dataset = DetectionDataset::open(test_data, true);
  const std::vector<std::size_t> indices = model_lidar_indices(detector.info(), dataset.lidar_names(), "test");
  std::vector<eval::DetectionFrame> frames;
  for (std::size_t k = 0; k < dataset.frames(); ++k) {
    const DetectionFrame frame = select_lidars(dataset.read(k), indices);
    frames.push_back({frame.id, frame.labels, {}, detector.detect(frame).boxes});
  }
  eval::DetectionEvalConfig config;
  config.classes = {io::ObjectClass::kCar};
  const eval::DetectionEvalResult result = eval::evaluate_detections(frames, config);
  return result.classes[0].levels[static_cast<std::size_t>(eval::IouLevel::kLoose)]
      .difficulties[static_cast<std::size_t>(eval::Difficulty::kHard)]
      .box_3d.ap_r40;
}

TEST(MlodEndToEnd, FindsIsolatedCarsInHeldOutFrames) {
  keep_large_buffers_in_the_heap();  // as the CLI does: half of a step went to mapping LibTorch's buffers afresh
  const fs::path dir = test::scratch_dir();
  const fs::path train = cars_dataset(dir / "train", 48, sim::DetectionSplit::kTrain);
  const fs::path test = cars_dataset(dir / "test", 8, sim::DetectionSplit::kTest);
  TrainRequest request;
  request.data = train;
  request.config.grid = {-28.8, 28.8, -28.8, 28.8, -3.0, 3.0, 0.4};  // the cars stand within 25 m
  request.config.channels = 16;
  request.config.threads = 1;  // ctest runs two tests at once on CI's two cores: two LibTorch threads ran 3x slower
  request.config.stage1.epochs = 40;
  request.config.stage1.learning_rate = 0.003;
  request.config.stage2.epochs = 5;
  request.config.inference.score_threshold = 0.1;
  request.out = dir / "model";
  train_detector(request);
  const Detector two_stage = Detector::load(dir / "model");
  ASSERT_TRUE(two_stage.refines());
  const double stage1_ap = ap3d_loose_hard(test, Detector::load(dir / "model", 1));
  const double mlod_ap = ap3d_loose_hard(test, two_stage);
  std::cout << "AP3D R40 at IoU 0.5, held-out frames: stage 1 " << stage1_ap << ", MLOD " << mlod_ap << '\n';
  EXPECT_GE(stage1_ap, 0.8);
  EXPECT_GE(mlod_ap, 0.8);
}

}  // namespace
}  // namespace mlidar::detect

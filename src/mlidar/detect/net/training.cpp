// `mlidar detect train`: stage 1 (6.6.1.5) and stage 2 (6.6.1.6) training loops, checkpoints and resumption.
// Deterministic for a seed: step s trains on frame order_e[s mod n] of epoch e = s / n (a permutation drawn from the
// seed and e) with an augmentation and perturbation drawn from (seed, stage, s), so a resumed run repeats exactly
// what an uninterrupted one does.
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>

#include "mlidar/core/error.hpp"
#include "mlidar/detect/net/detector.hpp"
#include "mlidar/detect/net/model_weights.hpp"
#include "mlidar/detect/net/stage2.hpp"
#include "mlidar/detect/net/training_folder.hpp"
#include "mlidar/detect/result_fusion.hpp"
#include "mlidar/eval/box_iou.hpp"

namespace mlidar::detect {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
constexpr long kLogEvery = 10;  ///< steps per line of train_log.jsonl (the mean loss of those steps)

/// What both stages share: the data, the model's LiDARs, the folder.
struct Session {
  const TrainRequest& request;
  const DetectConfig& config;
  DetectionDataset dataset;
  std::vector<std::size_t> lidar_indices;
  std::vector<std::size_t> train_frames;       ///< frames trained on
  std::vector<std::size_t> validation_frames;  ///< result fusion's temperatures
  net::TrainingRecord record;
  std::map<int, StageRecord> records;
  const std::function<void(const TrainProgress&)>& progress;
};

/// The training frame of step `step`: epoch-wise permutations of the training frames.
std::size_t frame_of_step(const Session& session, int stage, long step) {
  const auto n = static_cast<long>(session.train_frames.size());
  std::vector<std::size_t> order = session.train_frames;
  std::mt19937_64 rng(mix_seed(mix_seed(session.config.seed, static_cast<std::uint64_t>(stage)), static_cast<std::uint64_t>(step / n)));
  std::shuffle(order.begin(), order.end(), rng);
  return order[static_cast<std::size_t>(step % n)];
}

double cosine_rate(double base, long step, long steps) {
  const double progress = steps > 1 ? static_cast<double>(step) / static_cast<double>(steps - 1) : 1.0;
  return base * (0.1 + 0.9 * 0.5 * (1.0 + std::cos(std::numbers::pi * progress)));
}

void set_rate(torch::optim::Adam& optimizer, double rate) {
  for (auto& group : optimizer.param_groups()) static_cast<torch::optim::AdamOptions&>(group.options()).lr(rate);
}

/// Runs `steps_total` steps of `step_fn` (which returns the loss and its terms), with checkpoints, logging and
/// progress; resumes from the stage's checkpoint when there is one. Returns the stage's record.
StageRecord run_loop(Session& session, int stage, torch::nn::Module& module, torch::optim::Adam& optimizer, double base_rate,
                     long steps_total, const std::function<std::pair<double, std::map<std::string, double>>(long)>& step_fn) {
  const fs::path& out = session.request.out;
  const fs::path checkpoint = out / ("checkpoint_stage" + std::to_string(stage) + ".pt");
  long step = 0;
  if (fs::exists(checkpoint)) step = net::load_checkpoint(module, optimizer, checkpoint);
  const net::TrainingLog log(out);
  log.keep_until(stage, step);
  session.record.stages[stage] = {step, steps_total, false};
  net::write_training_record(out, session.record);
  const long first_step = step;
  // Checkpoints fall on the log's 10-step lines, so that a resumed run logs exactly what an uninterrupted one does.
  const long every = kLogEvery * ((session.config.stage1.checkpoint_every + kLogEvery - 1) / kLogEvery);
  const Clock::time_point start = Clock::now();
  double loss_sum = 0.0, last_loss = 0.0;
  std::map<std::string, double> term_sum;
  long summed = 0;
  const auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  const auto save = [&](long done) {
    net::save_checkpoint(module, optimizer, done, checkpoint);
    session.record.stages[stage].steps_done = done;
    net::write_training_record(out, session.record);
    log.write_plot();
  };
  module.train();
  for (; step < steps_total; ++step) {
    set_rate(optimizer, cosine_rate(base_rate, step, steps_total));
    const auto [loss, terms] = step_fn(step);
    loss_sum += loss, ++summed;
    for (const auto& [name, value] : terms) term_sum[name] += value;
    const long done = step + 1;
    if (done % kLogEvery == 0 || done == steps_total) {
      net::LogLine line{stage, done, step / static_cast<long>(session.train_frames.size()), loss_sum / summed, {}, 0.0, seconds()};
      for (const auto& [name, value] : term_sum) line.terms[name] = value / summed;
      line.learning_rate = cosine_rate(base_rate, step, steps_total);
      log.append(line);
      last_loss = line.loss;
      loss_sum = 0.0, summed = 0, term_sum.clear();
    }
    if (session.progress) session.progress({stage, done, steps_total, summed ? loss_sum / summed : last_loss, seconds(), first_step});
    if (done % every == 0) save(done);
  }
  save(steps_total);
  const double previous = session.records.contains(stage) ? session.records.at(stage).seconds : 0.0;
  return {steps_total, last_loss, previous + seconds()};
}

long stage_steps(const Session& session, int epochs) {
  const long steps = static_cast<long>(epochs) * static_cast<long>(session.train_frames.size());
  return session.request.max_steps > 0 ? std::min(steps, session.request.max_steps) : steps;
}

/// The points each batch item of stage 1 sees (for its targets): per LiDAR with result fusion, else all together
/// (`merged` holds them).
std::vector<std::span<const Vec3>> item_points(const DetectionFrame& frame, Fusion fusion, LidarPoints& merged) {
  std::vector<std::span<const Vec3>> items;
  if (fusion == Fusion::kResult) {
    for (const LidarPoints& lidar : frame.lidars) items.emplace_back(lidar.points);
    return items;
  }
  merged = merge_lidars(frame);
  return {merged.points};
}

/// Each LiDAR's score temperature from the validation frames' detections (eq 6.11's calibration); 1 without any.
void fit_temperatures(Session& session, net::BevNet& net) {
  const std::size_t lidars = session.lidar_indices.size();
  std::vector<std::vector<double>> logits(lidars);
  std::vector<std::vector<std::uint8_t>> positive(lidars);
  net->eval();
  torch::NoGradGuard no_grad;
  for (const std::size_t k : session.validation_frames) {
    const DetectionFrame frame = select_lidars(session.dataset.read(k), session.lidar_indices);
    const std::vector<io::Box3D> boxes = boxes_of_class(frame.labels, session.config.object_class);
    const std::vector<torch::Tensor> output = net::run_stage1(net, net::stage1_grids(frame, Fusion::kResult, session.config.grid), Fusion::kResult);
    for (std::size_t j = 0; j < lidars; ++j) {
      for (const net::Proposal& proposal : net::decode_stage1(output, static_cast<long>(j), session.config, 0.05)) {
        double best = 0.0;
        for (const io::Box3D& box : boxes) best = std::max(best, eval::iou_3d(proposal.box, box));
        logits[j].push_back(proposal.logit);
        positive[j].push_back(best >= 0.5 ? 1 : 0);
      }
    }
  }
  for (std::size_t j = 0; j < lidars; ++j) {
    const bool both = std::count(positive[j].begin(), positive[j].end(), 1) > 0 && std::count(positive[j].begin(), positive[j].end(), 0) > 0;
    session.record.temperatures[session.record.lidars[j]] = both ? fit_temperature(logits[j], positive[j]) : 1.0;
  }
}

/// The perturbation a training sample is read with (6.6.1.6): when `inject`, with probability `share` a level drawn
/// from `alphas`, else 0 (clean); and the seed of its draw.
std::pair<double, std::uint64_t> draw_perturbation(bool inject, double share, const std::vector<double>& alphas, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const bool uncertain = inject && unit(rng) < share;
  const double alpha = uncertain ? alphas[static_cast<std::size_t>(unit(rng) * alphas.size()) % alphas.size()] : 0.0;
  return {alpha, rng()};
}

/// Whether training draws perturbations (from stage2.alphas): not when the dataset's extrinsics are perturbed
/// already (its own alpha), and not without levels to draw.
bool draws_perturbations(const Session& session) {
  return session.dataset.dataset_alpha() == 0.0 && !session.config.stage2.alphas.empty();
}

void train_stage1(Session& session) {
  const DetectConfig& config = session.config;
  const Fusion fusion = session.record.fusion;
  torch::manual_seed(config.seed);
  net::BevNet net = net::make_stage1(config);
  torch::optim::Adam optimizer(net->parameters(), torch::optim::AdamOptions(config.stage1.learning_rate).weight_decay(config.stage1.weight_decay));
  const long steps = stage_steps(session, config.stage1.epochs);
  const bool inject = draws_perturbations(session);
  session.records[1] = run_loop(session, 1, *net, optimizer, config.stage1.learning_rate, steps, [&](long step) {
    std::mt19937_64 rng(mix_seed(mix_seed(config.seed, 1), static_cast<std::uint64_t>(step) + 1000003));
    // Stage 1 draws nothing unless asked to see perturbed frames (the thesis trains it on clean ones).
    const auto [alpha, perturbation_seed] = config.stage1.uncertain_share > 0.0
                                                ? draw_perturbation(inject, config.stage1.uncertain_share, config.stage2.alphas, rng)
                                                : std::pair<double, std::uint64_t>{0.0, 0};
    DetectionFrame frame =
        select_lidars(session.dataset.read(frame_of_step(session, 1, step), alpha, perturbation_seed), session.lidar_indices);
    augment_frame(draw_augmentation(config.augment, false, rng), frame);
    const std::vector<io::Box3D> boxes = boxes_of_class(frame.labels, config.object_class);
    const std::vector<torch::Tensor> output = net::run_stage1(net, net::stage1_grids(frame, fusion, config.grid), fusion);
    LidarPoints merged;
    const std::vector<std::span<const Vec3>> points = item_points(frame, fusion, merged);
    torch::Tensor total = torch::zeros({}, torch::kFloat32);
    std::map<std::string, double> terms;
    for (std::size_t item = 0; item < points.size(); ++item) {
      const net::Stage1Loss loss = net::stage1_loss(output, static_cast<long>(item), net::stage1_targets(boxes, points[item], config), config.stage1);
      total = total + loss.total / static_cast<double>(points.size());
      terms["classification"] += loss.classification.item<double>() / static_cast<double>(points.size());
      terms["regression"] += loss.regression.item<double>() / static_cast<double>(points.size());
      terms["direction"] += loss.direction.item<double>() / static_cast<double>(points.size());
    }
    terms["alpha"] = alpha;
    optimizer.zero_grad();
    total.backward();
    optimizer.step();
    return std::pair{total.item<double>(), terms};
  });
  if (fusion == Fusion::kResult) fit_temperatures(session, net);
  net::save_weights(*net, session.request.out / "stage1.pt");
  session.record.stages[1].done = true;
  net::write_training_record(session.request.out, session.record);
  net::write_model_for(session.request.out, session.record, config, session.records);
}

void train_stage2(Session& session) {
  const DetectConfig& config = session.config;
  const Fusion fusion = session.record.fusion;
  net::BevNet proposer = net::make_stage1(config);
  net::load_weights(*proposer, session.request.out / "stage1.pt");
  proposer->eval();
  std::vector<double> temperatures;
  for (const std::string& name : session.record.lidars) temperatures.push_back(session.record.temperatures.contains(name) ? session.record.temperatures.at(name) : 1.0);
  torch::manual_seed(config.seed + 2);
  net::Refiner refiner = net::make_stage2();
  torch::optim::Adam optimizer(refiner->parameters(), torch::optim::AdamOptions(config.stage2.learning_rate));
  const long steps = stage_steps(session, config.stage2.epochs);
  const bool inject = draws_perturbations(session);
  session.records[2] = run_loop(session, 2, *refiner, optimizer, config.stage2.learning_rate, steps, [&](long step) {
    std::mt19937_64 rng(mix_seed(mix_seed(config.seed, 2), static_cast<std::uint64_t>(step) + 1000003));
    // 6.6.1.6: about 1 clean sample for 1.5 uncertain ones, each uncertain one at a level drawn from the alphas.
    const auto [alpha, perturbation_seed] = draw_perturbation(inject, config.stage2.uncertain_share, config.stage2.alphas, rng);
    DetectionFrame frame = select_lidars(session.dataset.read(frame_of_step(session, 2, step), alpha, perturbation_seed), session.lidar_indices);
    augment_frame(draw_augmentation(config.augment, true, rng), frame);
    const std::vector<io::Box3D> boxes = boxes_of_class(frame.labels, config.object_class);
    std::vector<net::Proposal> proposals = net::stage1_proposals(proposer, frame, fusion, config, temperatures, 0.05);
    if (static_cast<int>(proposals.size()) > config.stage2.proposals) proposals.resize(static_cast<std::size_t>(config.stage2.proposals));
    for (const net::Proposal& extra : net::jittered_truths(boxes, config.stage2.jittered_truths, rng)) proposals.push_back(extra);
    if (proposals.size() < 2) return std::pair{0.0, std::map<std::string, double>{}};  // nothing to learn from (BatchNorm needs two)
    const net::Stage2Input input = net::stage2_input(merge_lidars(frame), proposals, config);
    const net::Stage2Targets targets = net::stage2_targets(proposals, boxes, config.stage2);
    const net::Stage2Loss loss = net::stage2_loss(refiner->forward(input.points, input.proposals), targets, input, config.stage2);
    optimizer.zero_grad();
    loss.total.backward();
    optimizer.step();
    return std::pair{loss.total.item<double>(), std::map<std::string, double>{{"classification", loss.classification.item<double>()},
                                                                              {"regression", loss.regression.item<double>()},
                                                                              {"uncertainty", loss.uncertainty.item<double>()},
                                                                              {"alpha", alpha}}};
  });
  net::save_weights(*refiner, session.request.out / "stage2.pt");
  session.record.stages[2].done = true;
  net::write_training_record(session.request.out, session.record);
  net::write_model_for(session.request.out, session.record, config, session.records);
}

std::vector<std::size_t> chosen_lidars(const TrainRequest& request, const DetectionDataset& dataset) {
  const auto& names = dataset.lidar_names();
  if (request.fusion != Fusion::kNone) {
    if (!request.lidar.empty()) throw UsageError("--lidar " + request.lidar + ": only with --fusion none (one LiDAR alone)");
    std::vector<std::size_t> all(names.size());
    std::iota(all.begin(), all.end(), std::size_t{0});
    return all;
  }
  const auto it = std::find(names.begin(), names.end(), request.lidar);
  if (request.lidar.empty() || it == names.end()) {
    std::string known;
    for (const std::string& name : names) known += (known.empty() ? "" : ", ") + name;
    throw UsageError("--fusion none needs --lidar NAME, one of the dataset's LiDARs: " + known);
  }
  return {static_cast<std::size_t>(it - names.begin())};
}

}  // namespace

void train_detector(const TrainRequest& request, const std::function<void(const TrainProgress&)>& progress) {
  DetectionDataset dataset = DetectionDataset::open(request.data, /*need_labels=*/true);
  const std::vector<std::size_t> indices = chosen_lidars(request, dataset);
  std::vector<std::string> lidars;
  for (const std::size_t j : indices) lidars.push_back(dataset.lidar_names()[j]);
  net::TrainingRecord record = net::open_training_folder(request, lidars);
  if (record.lidars != lidars) {
    throw InputError((request.out / "training.json").string(), "lidars", "this training reads other LiDARs than the dataset gives");
  }
  torch::set_num_threads(request.config.threads);
  Session session{request, request.config, std::move(dataset), indices, {}, {}, std::move(record), {}, progress};
  const std::size_t frames = session.dataset.frames();
  const std::size_t validation =
      session.record.fusion == Fusion::kResult ? static_cast<std::size_t>(std::floor(request.config.validation_share * frames)) : 0;
  for (std::size_t k = 0; k < frames; ++k) (k < frames - validation ? session.train_frames : session.validation_frames).push_back(k);
  if (fs::exists(request.out / "model.json")) session.records = read_model_folder(request.out).info.records;
  const bool want1 = request.stage != 2, want2 = request.stage != 1;
  if (want1 && !(session.record.stages.contains(1) && session.record.stages.at(1).done)) train_stage1(session);
  if (want2 && !(session.record.stages.contains(2) && session.record.stages.at(2).done)) train_stage2(session);
}

}  // namespace mlidar::detect

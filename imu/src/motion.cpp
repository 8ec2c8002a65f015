// Simulated head motion. Every generator is a closed-form pose curve (orientation, position) of
// time; angular velocity and linear acceleration are derived from it numerically, so the gyro
// and accelerometer the emulator synthesises are always consistent with the ground truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "motion_internal.h"

namespace steadyxr::imu {

double MotionStream::headSpeedDegPerSec(double tSec) const {
  return glm::length(glm::dvec3(at(tSec).angularVelocityRadPerSec)) / detail::kDegToRad;
}

namespace {

using namespace detail;

class Fixation final : public PoseStream {
 public:
  Fixation(const FixationParams& p, uint64_t seed) : p_(p), seed_(seed) {
    JitterParams j;
    j.periodSec = p.durationSec + 2.0;
    j.tremorAmplitudeDeg = p.tremorAmplitudeDeg;
    j.tremorLowHz = std::min(p.tremorLowHz, p.tremorHighHz);
    j.tremorHighHz = std::max(p.tremorLowHz, p.tremorHighHz);
    j.driftDegPerSec = p.driftDegPerSec;
    j.translationTremorMm = p.translationTremorMm;
    jitter_ = Jitter(j, seed);
    Rng rng(seed ^ 0x5ACCADEull);
    if (p.jumpsPerSec > 0.0 && p.jumpAmplitudeDeg != 0.0) {
      for (double t = rng.exponential(p.jumpsPerSec); t < p.durationSec;
           t += rng.exponential(p.jumpsPerSec)) {
        jumps_.push_back({t, std::max(p.jumpRampSec, 1e-3),
                          rng.unitVector() * (p.jumpAmplitudeDeg * rng.uniform(0.5, 1.5))});
        if (jumps_.size() > 100000) break;
      }
    }
  }

  Pose poseAt(double t) const override {
    dvec3 deg = jitter_.rotationDeg(t);
    for (const auto& j : jumps_) deg += j.at(t);
    Pose pose;
    pose.q = fromRotationVector(deg * kDegToRad);
    pose.p = neckTranslation(pose.q) + jitter_.translation(t);
    return pose;
  }
  double durationSec() const override { return p_.durationSec; }
  std::vector<double> motionChangeTimes() const override {
    std::vector<double> out;
    for (const auto& j : jumps_) out.push_back(j.t);
    return out;
  }
  std::string describe() const override {
    return formatText("fixation(%.1fs tremor %.3fdeg %.0f-%.0fHz drift %.2fdeg/s jumps %.2f/s seed %llu)",
                      p_.durationSec, p_.tremorAmplitudeDeg, p_.tremorLowHz, p_.tremorHighHz,
                      p_.driftDegPerSec, p_.jumpsPerSec, static_cast<unsigned long long>(seed_));
  }

 private:
  FixationParams p_;
  uint64_t seed_;
  Jitter jitter_;
  std::vector<Jump> jumps_;
};

class Turn final : public PoseStream {
 public:
  Turn(const TurnParams& p, std::string name) : p_(p), name_(std::move(name)) {
    duration_ = std::max(p.durationSec, 1e-3);
    ramp_ = std::clamp(p.rampSec, 0.0, duration_ / 2.0);
    speed_ = p.peakSpeedDegPerSec * kDegToRad;
    const dvec3 axis(p.axis);
    axis_ = glm::length(axis) > 1e-9 ? glm::normalize(axis) : dvec3(0.0, 1.0, 0.0);
  }

  Pose poseAt(double t) const override {
    Pose pose;
    pose.q = glm::angleAxis(rampedTurnAngle(t, duration_, ramp_, ramp_, speed_), axis_);
    pose.p = neckTranslation(pose.q);
    return pose;
  }
  double durationSec() const override { return duration_; }
  std::vector<double> motionChangeTimes() const override { return {0.0, duration_}; }
  std::string describe() const override {
    return formatText("%s(%.1fdeg/s for %.2fs, ramp %.2fs, axis %.2f %.2f %.2f)", name_.c_str(),
                      p_.peakSpeedDegPerSec, duration_, ramp_, axis_.x, axis_.y, axis_.z);
  }

 private:
  TurnParams p_;
  std::string name_;
  double duration_, ramp_, speed_;
  dvec3 axis_;
};

class Sequence final : public MotionStream {
 public:
  explicit Sequence(std::vector<std::unique_ptr<MotionStream>> parts) : parts_(std::move(parts)) {
    dquat anchorQ(1.0, 0.0, 0.0, 0.0);
    dvec3 anchorP(0.0);
    double start = 0.0;
    for (const auto& part : parts_) {
      Segment seg;
      seg.start = start;
      seg.duration = std::max(part->durationSec(), 0.0);
      const MotionState s0 = part->at(0.0);
      // Rotates the part so that its first pose lands on the previous part's last pose.
      seg.rotation = anchorQ * glm::conjugate(dquat(s0.orientation));
      seg.anchorP = anchorP;
      seg.p0 = dvec3(s0.position);
      segments_.push_back(seg);
      const MotionState end = part->at(seg.duration);
      anchorQ = glm::normalize(seg.rotation * dquat(end.orientation));
      anchorP = seg.anchorP + seg.rotation * (dvec3(end.position) - seg.p0);
      start += seg.duration;
    }
    total_ = start;
  }

  MotionState at(double t) const override {
    if (parts_.empty()) return {};
    t = std::max(t, 0.0);
    size_t i = 0;
    while (i + 1 < segments_.size() && t >= segments_[i + 1].start) ++i;
    const Segment& seg = segments_[i];
    const MotionState s = parts_[i]->at(t - seg.start);
    MotionState out;
    out.orientation = glm::quat(glm::normalize(seg.rotation * dquat(s.orientation)));
    out.angularVelocityRadPerSec = s.angularVelocityRadPerSec;  // head frame: unchanged
    out.position = glm::vec3(seg.anchorP + seg.rotation * (dvec3(s.position) - seg.p0));
    out.linearAccelerationMps2 = glm::vec3(seg.rotation * dvec3(s.linearAccelerationMps2));
    return out;
  }
  double durationSec() const override { return total_; }
  double validUntilSec() const override {
    if (segments_.empty()) return 0.0;
    return segments_.back().start + parts_.back()->validUntilSec();
  }
  std::vector<double> motionChangeTimes() const override {
    std::vector<double> out;
    for (size_t i = 0; i < parts_.size(); ++i)
      for (double t : parts_[i]->motionChangeTimes())
        if (t <= segments_[i].duration + 1e-9) out.push_back(segments_[i].start + t);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end(), [](double a, double b) { return b - a < 1e-6; }),
              out.end());
    return out;
  }
  std::string describe() const override {
    std::string s = "sequence[";
    for (size_t i = 0; i < parts_.size(); ++i) s += (i ? ", " : "") + parts_[i]->describe();
    return s + "]";
  }

 private:
  struct Segment {
    double start = 0.0, duration = 0.0;
    dquat rotation{1.0, 0.0, 0.0, 0.0};
    dvec3 anchorP{0.0}, p0{0.0};
  };
  std::vector<std::unique_ptr<MotionStream>> parts_;
  std::vector<Segment> segments_;
  double total_ = 0.0;
};

class Trace final : public PoseStream {
 public:
  struct Row {
    double t;
    dquat q;
    dvec3 w, p;
  };
  Trace(std::vector<Row> rows, bool hasOmega, std::string path)
      : rows_(std::move(rows)), hasOmega_(hasOmega), path_(std::move(path)) {
    double minDt = 1.0;
    for (size_t i = 1; i < rows_.size(); ++i) minDt = std::min(minDt, rows_[i].t - rows_[i - 1].t);
    step_ = std::clamp(minDt / 2.0, 1e-5, 1e-2);
  }

  Pose poseAt(double t) const override {
    const auto [i, f] = locate(t);
    const Row& a = rows_[i];
    const Row& b = rows_[std::min(i + 1, rows_.size() - 1)];
    return {glm::normalize(glm::slerp(a.q, b.q, f)), glm::mix(a.p, b.p, f)};
  }
  double derivativeStep() const override { return step_; }

  MotionState at(double t) const override {
    MotionState s = PoseStream::at(t);
    if (hasOmega_) {
      const auto [i, f] = locate(std::max(t, 0.0));
      const Row& a = rows_[i];
      const Row& b = rows_[std::min(i + 1, rows_.size() - 1)];
      s.angularVelocityRadPerSec = glm::vec3(glm::mix(a.w, b.w, f));
    }
    return s;
  }
  double durationSec() const override { return rows_.back().t; }
  double validUntilSec() const override { return rows_.back().t; }
  std::string describe() const override {
    return "trace(" + path_ + ", " + std::to_string(rows_.size()) + " rows)";
  }

 private:
  std::pair<size_t, double> locate(double t) const {
    if (t <= rows_.front().t) return {0, 0.0};
    if (t >= rows_.back().t) return {rows_.size() - 1, 0.0};
    const auto it =
        std::upper_bound(rows_.begin(), rows_.end(), t, [](double x, const Row& r) { return x < r.t; });
    const size_t i = static_cast<size_t>(it - rows_.begin()) - 1;
    return {i, (t - rows_[i].t) / (rows_[i + 1].t - rows_[i].t)};
  }

  std::vector<Row> rows_;
  bool hasOmega_;
  std::string path_;
  double step_ = 1e-4;
};

void setError(std::string* error, const std::string& msg) {
  if (error) *error = msg;
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? std::string() : cell.substr(b, e - b + 1));
  }
  return out;
}

}  // namespace

TurnParams fastTurnDefaults() {
  TurnParams p;
  p.durationSec = 0.6;
  p.peakSpeedDegPerSec = 200.0;
  p.rampSec = 0.15;
  return p;
}

std::unique_ptr<MotionStream> makeFixation(const FixationParams& p, uint64_t seed) {
  return std::make_unique<Fixation>(p, seed);
}

std::unique_ptr<MotionStream> makePursuit(const TurnParams& p, uint64_t /*seed: a pure turn*/) {
  return std::make_unique<Turn>(p, "pursuit");
}

std::unique_ptr<MotionStream> makeFastTurn(const TurnParams& p, uint64_t /*seed*/) {
  const TurnParams d{};
  const bool isDefault = p.durationSec == d.durationSec && p.peakSpeedDegPerSec == d.peakSpeedDegPerSec &&
                         p.rampSec == d.rampSec && p.axis == d.axis;
  return std::make_unique<Turn>(isDefault ? fastTurnDefaults() : p, "fastturn");
}

std::unique_ptr<MotionStream> makeSequence(std::vector<std::unique_ptr<MotionStream>> parts) {
  std::erase(parts, nullptr);
  return std::make_unique<Sequence>(std::move(parts));
}

std::unique_ptr<MotionStream> loadTrace(const std::string& path, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    setError(error, "cannot open trace file '" + path + "'");
    return nullptr;
  }
  std::string line;
  if (!std::getline(in, line)) {
    setError(error, "trace '" + path + "' is empty");
    return nullptr;
  }
  const auto header = splitCsv(line);
  auto col = [&](std::initializer_list<const char*> names) -> int {
    for (size_t i = 0; i < header.size(); ++i)
      for (const char* n : names)
        if (header[i] == n) return static_cast<int>(i);
    return -1;
  };
  const int ct = col({"t_s", "t", "time"});
  const int cq[4] = {col({"qw"}), col({"qx"}), col({"qy"}), col({"qz"})};
  const int cw[3] = {col({"wx"}), col({"wy"}), col({"wz"})};
  const int cp[3] = {col({"px"}), col({"py"}), col({"pz"})};
  const bool hasQ = cq[0] >= 0 && cq[1] >= 0 && cq[2] >= 0 && cq[3] >= 0;
  const bool hasW = cw[0] >= 0 && cw[1] >= 0 && cw[2] >= 0;
  const bool hasP = cp[0] >= 0 && cp[1] >= 0 && cp[2] >= 0;
  if (ct < 0 || (!hasQ && !hasW)) {
    setError(error, "trace '" + path + "': header needs t_s and qw,qx,qy,qz and/or wx,wy,wz");
    return nullptr;
  }
  std::vector<Trace::Row> rows;
  int lineNo = 1;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    const auto cells = splitCsv(line);
    auto num = [&](int c, double* v) {
      if (c < 0 || static_cast<size_t>(c) >= cells.size() || cells[c].empty()) return false;
      char* end = nullptr;
      *v = std::strtod(cells[c].c_str(), &end);
      return end && *end == '\0' && std::isfinite(*v);
    };
    Trace::Row r{0.0, dquat(1.0, 0.0, 0.0, 0.0), dvec3(0.0), dvec3(0.0)};
    bool ok = num(ct, &r.t);
    if (hasQ) ok = ok && num(cq[0], &r.q.w) && num(cq[1], &r.q.x) && num(cq[2], &r.q.y) && num(cq[3], &r.q.z);
    if (hasW) ok = ok && num(cw[0], &r.w.x) && num(cw[1], &r.w.y) && num(cw[2], &r.w.z);
    if (hasP) ok = ok && num(cp[0], &r.p.x) && num(cp[1], &r.p.y) && num(cp[2], &r.p.z);
    if (ok && hasQ) {
      const double n = glm::length(r.q);
      ok = n > 0.5 && n < 1.5;
      if (ok) r.q = r.q / n;
    }
    if (!ok) {
      setError(error, "trace '" + path + "' line " + std::to_string(lineNo) + ": malformed row");
      return nullptr;
    }
    if (!rows.empty() && r.t <= rows.back().t) {
      setError(error, "trace '" + path + "' line " + std::to_string(lineNo) + ": time does not increase");
      return nullptr;
    }
    rows.push_back(r);
  }
  if (rows.size() < 2) {
    setError(error, "trace '" + path + "' needs at least two rows");
    return nullptr;
  }
  const double t0 = rows.front().t;
  for (auto& r : rows) r.t -= t0;
  if (!hasQ) {  // integrate angular velocity (head frame), trapezoidal
    rows[0].q = dquat(1.0, 0.0, 0.0, 0.0);
    for (size_t i = 1; i < rows.size(); ++i) {
      const dvec3 w = 0.5 * (rows[i - 1].w + rows[i].w);
      rows[i].q = glm::normalize(rows[i - 1].q * fromRotationVector(w * (rows[i].t - rows[i - 1].t)));
    }
  }
  for (size_t i = 1; i < rows.size(); ++i)  // keep quaternion signs continuous for slerp
    if (glm::dot(rows[i - 1].q, rows[i].q) < 0.0) rows[i].q = -rows[i].q;
  return std::make_unique<Trace>(std::move(rows), hasW, path);
}

bool writeTrace(const MotionStream& stream, double rateHz, double durationSec, const std::string& path,
                std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    setError(error, "cannot write '" + path + "'");
    return false;
  }
  std::fprintf(f, "t_s,qw,qx,qy,qz,wx,wy,wz,px,py,pz\n");
  const auto n = static_cast<long long>(std::floor(durationSec * rateHz + 1e-9));
  for (long long i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / rateHz;
    const MotionState s = stream.at(t);
    std::fprintf(f, "%.6f,%.9f,%.9f,%.9f,%.9f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", t, s.orientation.w,
                 s.orientation.x, s.orientation.y, s.orientation.z, s.angularVelocityRadPerSec.x,
                 s.angularVelocityRadPerSec.y, s.angularVelocityRadPerSec.z, s.position.x, s.position.y,
                 s.position.z);
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok) setError(error, "error writing '" + path + "'");
  return ok;
}

}  // namespace steadyxr::imu

#include "simulation/simulated_world.h"

#include <cmath>

#include "arbci/core/seeds.h"

namespace arbci::session {

SimulatedWorld::SimulatedWorld(const SceneSettings& settings) : settings_(settings) {
  const CameraSettings& c = settings.cameras;
  camera_.image_size = {c.width, c.height};
  camera_.camera_matrix =
      cv::Matx33d(c.focal_px, 0, c.width / 2.0 - 0.5, 0, c.focal_px, c.height / 2.0 - 0.5, 0, 0, 1);
  camera_.distortion = c.distortion;
  camera_.source = "simulated camera";
  const WorldSettings& w = settings.world;
  scene_.table_z = w.table_z;
  scene_.reference = {vision::MarkerKind::Bch, w.reference_id, w.reference_size_m,
                      settings.marker_border};
  scene_.T_world_reference = {cv::Matx33d::eye(), w.reference_position};
  for (const WorldObjectSettings& o : w.objects) {
    SceneObject object;
    object.marker = {settings.marker_kind, o.id, o.marker_m, settings.marker_border};
    object.T_world_top = {cv::Matx33d::eye(), o.position};
    object.width_m = o.width_m;
    object.height_m = o.height_m;
    object.color = cv::Vec3f(static_cast<float>(o.color[0]), static_cast<float>(o.color[1]),
                             static_cast<float>(o.color[2]));
    scene_.objects.push_back(object);
  }
  left_ = std::make_unique<SimulatedCamera>(
      camera_, core::seedOf(settings.seed, core::RandomStream::LeftCamera));
  right_ = std::make_unique<SimulatedCamera>(
      camera_, core::seedOf(settings.seed, core::RandomStream::RightCamera));
  approach_height_ = robotConfig().approach_height;
}

SimulatedWorld::~SimulatedWorld() = default;

robot::RobotConfig SimulatedWorld::robotConfig() const {
  robot::RobotConfig r;
  r.table_z = settings_.world.table_z;
  r.workspace_min = {-0.7, 0.2, settings_.world.table_z};
  r.workspace_max = {0.7, 1.0, settings_.world.table_z + 0.6};
  r.speed_factor = settings_.robot_speed_factor;
  for (const WorldObjectSettings& o : settings_.world.objects) {
    robot::SimulatedObject object(o.id, {o.position[0], o.position[1], o.position[2]}, o.height_m,
                                  o.width_m / 2.0);
    object.mass = o.mass_kg;
    object.friction = o.friction;
    r.objects.push_back(object);
  }
  return r;
}

void SimulatedWorld::update(const robot::StatusPayload& status) {
  for (const robot::WorldObject& reported : status.objects) {
    for (SceneObject& o : scene_.objects) {
      const cv::Vec3d p(reported.position.x, reported.position.y, reported.position.z);
      const cv::Matx33d r = vision::rotationFromQuaternion(reported.orientation);
      if (o.marker.id == reported.id &&
          (p != o.T_world_top.translation || r != o.T_world_top.rotation)) {
        o.T_world_top = {r, p};
        ++scene_revision_;
      }
    }
  }
  const cv::Vec3d tool(status.tool.x, status.tool.y, status.tool.z);
  for (SceneObject& o : scene_.objects) {
    // Coming down on an object to grasp it, the gripper's fingertip passes over a corner of its
    // marker: from the arm's approach height above the top until it holds the object (within
    // 2 cm of the top's centre: the arm goes where the cameras saw the object).
    const cv::Vec3d top = o.T_world_top.translation;
    const bool over = status.current_command == robot::MessageType::Grasp &&
                      status.holding != o.marker.id &&
                      std::hypot(tool[0] - top[0], tool[1] - top[1]) < 0.02 &&
                      tool[2] <= top[2] + approach_height_ + 1e-3 && tool[2] > top[2] - o.height_m;
    if (o.gripper_over_corner != over) {
      o.gripper_over_corner = over;
      ++scene_revision_;
    }
  }
  if (!scene_.gripper || scene_.gripper->tool != tool ||
      scene_.gripper->opening != status.gripper_opening) {
    scene_.gripper = SceneGripper{tool, status.gripper_opening};
    ++scene_revision_;
  }
}

vision::Pose SimulatedWorld::leftCamera(double t) const {
  const CameraSettings& c = settings_.cameras;
  // Slow, small head motion: a few millimetres and a fraction of a degree.
  const cv::Vec3d sway(c.head_motion_m * std::sin(0.7 * t),
                       c.head_motion_m * 0.6 * std::sin(0.45 * t + 1.0),
                       c.head_motion_m * 0.4 * std::sin(0.3 * t + 2.0));
  const double look =
      std::tan(c.head_motion_deg * M_PI / 180.0) * cv::norm(c.look_at - c.head_position);
  const cv::Vec3d gaze(look * std::sin(0.5 * t + 0.3), look * 0.5 * std::sin(0.37 * t), 0.0);
  const vision::Pose head = vision::cameraLookingAt(c.head_position + sway, c.look_at + gaze);
  // The left camera sits half a baseline to the left (-x of the camera).
  vision::Pose left = head;
  left.translation += cv::Vec3d(c.baseline_m / 2.0, 0, 0);
  return left;
}

vision::Pose SimulatedWorld::T_right_left() const {
  return vision::Pose{cv::Matx33d::eye(), cv::Vec3d(-settings_.cameras.baseline_m, 0, 0)};
}

vision::Pose SimulatedWorld::rightCamera(double t) const {
  return T_right_left() * leftCamera(t);
}

SimulatedWorld::Frame SimulatedWorld::capture(SimulatedCamera& camera, Cache& cache,
                                              const vision::Pose& pose) {
  const bool moved = !cache.pose || pose.translation != cache.pose->translation ||
                     pose.rotation != cache.pose->rotation;
  if (!moved && cache.scene_revision == scene_revision_ && !cache.image.empty())
    return {cache.image, false};
  CameraEffects effects;
  effects.distort = !camera_.distortion.empty();
  effects.noise_sigma = settings_.cameras.noise;
  effects.blur_sigma = settings_.cameras.blur_px;
  effects.vignetting = 0.15;
  cache.image = camera.render(scene_, pose, effects);
  cache.pose = pose;
  cache.scene_revision = scene_revision_;
  return {cache.image, true};
}

void SimulatedWorld::coverAt(double t) {
  for (size_t i = 0; i < scene_.objects.size(); ++i) {
    const std::vector<double>& spans = settings_.world.objects[i].covered_s;
    bool covered = false;
    for (size_t k = 0; k + 1 < spans.size(); k += 2) covered |= t >= spans[k] && t < spans[k + 1];
    if (scene_.objects[i].covered != covered) {
      scene_.objects[i].covered = covered;
      ++scene_revision_;
    }
  }
}

SimulatedWorld::Frame SimulatedWorld::captureLeft(double t) {
  coverAt(t);
  return capture(*left_, left_cache_, leftCamera(t));
}

SimulatedWorld::Frame SimulatedWorld::captureRight(double t) {
  coverAt(t);
  return capture(*right_, right_cache_, rightCamera(t));
}

void SimulatedWorld::holdBoard(bool show, double t) {
  ++scene_revision_;
  if (!show) {
    scene_.board.reset();
    return;
  }
  // (tilt about x, tilt about y, right, down, distance) in the camera's frame.
  static const double kPoses[][5] = {
      {0, 0, 0, 0, 0.55},         {25, 0, 0, 0, 0.6},           {-25, 0, 0, 0, 0.6},
      {0, 30, 0, 0, 0.6},         {0, -30, 0, 0, 0.6},          {15, 15, -0.12, -0.08, 0.7},
      {-15, 20, 0.12, 0.08, 0.7}, {20, -20, 0.12, -0.08, 0.65}, {-20, -15, -0.12, 0.08, 0.65},
      {10, 0, 0, 0.1, 0.5},       {0, 10, -0.14, 0, 0.75},      {30, 10, 0.05, 0.05, 0.8}};
  const double* p = kPoses[board_pose_++ % 12];
  const double ax = p[0] * M_PI / 180.0, ay = p[1] * M_PI / 180.0;
  const cv::Matx33d tilt_x(1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax));
  const cv::Matx33d tilt_y(std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay));
  // Facing the camera: the board's y up is the camera's -y, its z (out of the print) the camera's
  // -z.
  const vision::Pose T_cam_board{tilt_x * tilt_y * cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1),
                                 cv::Vec3d(p[2], p[3], p[4])};
  SceneBoard board;
  board.T_world_board = leftCamera(t).inverse() * T_cam_board;
  scene_.board = board;
}

std::optional<cv::Vec3d> SimulatedWorld::objectPosition(int id) const {
  for (const SceneObject& o : scene_.objects) {
    if (o.marker.id == id) return o.T_world_top.translation;
  }
  return std::nullopt;
}

}  // namespace arbci::session

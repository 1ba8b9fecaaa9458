#include "sphere_tree_collision/ros/marker_publisher.hpp"

#include <algorithm>
#include <cmath>

namespace stc_ros {
namespace {

MarkerOptions markerOptionsOf(const NodeParams& params) {
  MarkerOptions o;
  o.frame = params.world_frame;
  o.levels = params.marker_levels;
  o.voxels = params.show_voxels;
  o.static_trees = params.static_tree_markers;
  o.static_voxels = params.static_voxel_markers;
  o.max_contacts = static_cast<std::size_t>(params.max_contact_markers);
  o.contact_size = params.contact_marker_size;
  return o;
}

}  // namespace

MarkerPublisher::MarkerPublisher(ros::NodeHandle& nh, const NodeParams& params, const stc::World& world,
                                 EntityLooks looks, GazeSource gaze, Guard guard)
    : world_(world),
      looks_(looks),
      gaze_(std::move(gaze)),
      mode_(params.marker_mode),
      keyframe_period_s_(params.marker_keyframe_period),
      options_(markerOptionsOf(params)) {
  // Arrays come from the tick, so that each shows the state of one tick and
  // carries that tick's stamp.
  ticks_per_marker_ = ticksPerMessage(params.rate, params.marker_rate);
  if (mode_ == NodeParams::MarkerMode::Incremental) {
    pub_ = nh.advertise<visualization_msgs::MarkerArray>(
        "markers", 100, [this, guard](const ros::SingleSubscriberPublisher& s) {
          guard("marker snapshot", [&] { sendSnapshot(s); });
        });
  } else {
    pub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 2);
  }
  bound_options_.frame = params.world_frame;
  bound_options_.max_bounds = options_.max_contacts;
  // Each array deletes only the bounds beyond its own count: one dropped array
  // would leave stale spheres drawn, so none is dropped under a slow reader.
  bounds_pub_ = nh.advertise<visualization_msgs::MarkerArray>("error_bounds", 100);
}

void MarkerPublisher::onTick(std::uint64_t tick, const stc::TickReport& report, const ros::Time& stamp) {
  last_stamp_ = stamp;
  if (tick % ticks_per_marker_ != 0) return;
  publish(stamp);
  publishBounds(report, stamp);
}

void MarkerPublisher::publishBounds(const stc::TickReport& report, const ros::Time& stamp) {
  if (bounds_pub_.getNumSubscribers() == 0) {
    bounds_.forget();
    return;
  }
  bounds_.build(world_, report, gaze_(), stamp, bound_options_, bounds_msg_);
  bounds_pub_.publish(bounds_msg_);
}

void MarkerPublisher::entityRemoved(stc::EntityId id, stc::ShapeId shape, bool is_static) {
  if (sent_.erase(id) != 0) removed_.push_back({id, shape, is_static});
}

void MarkerPublisher::worldCleared() {
  sent_.clear();
  removed_.clear();
  cleared_ = true;
}

void MarkerPublisher::retune(const NodeParams& next) {
  ticks_per_marker_ = ticksPerMessage(next.rate, next.marker_rate);
  if (next.marker_levels == options_.levels && next.show_voxels == options_.voxels) return;
  options_.levels = next.marker_levels;
  options_.voxels = next.show_voxels;
  worldCleared();
}

void MarkerPublisher::releaseMemory() {
  msg_ = visualization_msgs::MarkerArray();  // each array is built from its start
  bounds_msg_.markers.shrink_to_fit();
  colors_by_index_.shrink_to_fit();
  removed_.shrink_to_fit();
  sent_.rehash(0);
}

void MarkerPublisher::publish(const ros::Time& stamp) {
  if (pub_.getNumSubscribers() == 0) {
    // Nobody to keep up to date: the next subscriber starts from a snapshot.
    sent_.clear();
    removed_.clear();
    cleared_ = false;
    return;
  }
  const auto& ids = world_.entityIds();
  if (mode_ == NodeParams::MarkerMode::Full) {
    colors_by_index_.resize(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) colors_by_index_[i] = looks_.colors.at(ids[i]);
    builder_.buildFull(world_, colors_by_index_, options_, gaze_(), stamp, msg_);
    pub_.publish(msg_);
    return;
  }
  // A keyframe now and then repairs what a subscriber dropped (its queue may
  // overflow while rviz renders slowly); in between, only what changed.
  const ros::WallTime wall = ros::WallTime::now();
  if (keyframe_period_s_ > 0.0 && (wall - last_keyframe_).toSec() >= keyframe_period_s_) {
    last_keyframe_ = wall;
    buildSnapshot(stamp, true, msg_);
    pub_.publish(msg_);
    return;
  }
  builder_.begin(msg_);
  if (cleared_) {
    builder_.deleteAll(options_, msg_);
    builder_.forgetDynamic();
    cleared_ = false;
  }
  for (const Removed& r : removed_) builder_.deleteEntity(world_, r.id, r.shape, r.is_static, options_, msg_);
  removed_.clear();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!sent_.insert(ids[i]).second) continue;
    builder_.addEntity(world_, i, looks_.colors.at(ids[i]), looks_.frames.at(ids[i]), true, options_, stamp, msg_);
  }
  builder_.addDynamic(world_, options_, gaze_(), stamp, true, msg_);
  builder_.end(msg_);
  if (!msg_.markers.empty()) pub_.publish(msg_);  // nothing changed: nothing to send
}

void MarkerPublisher::buildSnapshot(const ros::Time& stamp, bool for_everyone, visualization_msgs::MarkerArray& out) {
  builder_.begin(out);
  builder_.deleteAll(options_, out);
  if (for_everyone) builder_.forgetDynamic();
  const auto& ids = world_.entityIds();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    builder_.addEntity(world_, i, looks_.colors.at(ids[i]), looks_.frames.at(ids[i]), true, options_, stamp, out);
  }
  builder_.addDynamic(world_, options_, gaze_(), stamp, for_everyone, out);
  builder_.end(out);
  if (for_everyone) {  // every subscriber now has exactly this
    sent_.clear();
    sent_.insert(ids.begin(), ids.end());
    removed_.clear();
    cleared_ = false;
  }
}

void MarkerPublisher::sendSnapshot(const ros::SingleSubscriberPublisher& subscriber) {
  // Alone, the newcomer defines what subscribers have. With others, the shared
  // state stays theirs and the next array brings the newcomer what is pending
  // as well (twice is harmless: an ADD replaces).
  visualization_msgs::MarkerArray snapshot;
  buildSnapshot(last_stamp_, pub_.getNumSubscribers() <= 1, snapshot);
  subscriber.publish(snapshot);
}

}  // namespace stc_ros

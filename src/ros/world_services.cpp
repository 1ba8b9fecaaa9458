#include "sphere_tree_collision/ros/world_services.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/tick_clock.hpp"

#include <boost/make_shared.hpp>

#include <chrono>
#include <exception>
#include <future>
#include <stdexcept>

namespace stc_ros {
namespace {

// A new tf listener's first second: frames it has not heard of yet may still come.
constexpr double kTfFillSeconds = 1.0;
// How long a spawn in another frame waits for tf to reach the request's stamp
// (on ~spawn's own thread: the world ticks on meanwhile).
constexpr double kTfStampWaitSeconds = 5.0;
constexpr std::uint32_t kMaxStepTicks = 100000;

// Runs `action`; a failure becomes success = false and "<field>: <reason>".
template <typename Response, typename F>
void answer(Response& res, const char* service, F&& action) {
  try {
    action();
    res.success = true;
    res.message = "";
  } catch (const stc::InputError& e) {
    res.success = false;
    res.message = e.field() + ": " + e.reason();
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("message: ") + e.what();
  }
  if (!res.success) ROS_WARN("~%s refused: %s", service, res.message.c_str());
}

// One piece of work queued on the node's spinner; `done` is kept or broken by it.
class TickThreadCall final : public ros::CallbackInterface {
 public:
  explicit TickThreadCall(std::function<void()> work) : work_(std::move(work)) {}
  CallResult call() override {
    try {
      work_();
      done_.set_value();
    } catch (...) {
      done_.set_exception(std::current_exception());
    }
    return Success;
  }
  std::future<void> done() { return done_.get_future(); }

 private:
  std::function<void()> work_;
  std::promise<void> done_;
};

}  // namespace

WorldServices::WorldServices(ros::NodeHandle& pnh, WorldControl& node)
    : node_(node), world_frame_(node.worldFrame()), spawn_spinner_(1, &spawn_queue_) {
  ros::AdvertiseServiceOptions spawn_options;
  spawn_options.init<sphere_tree_collision::Spawn::Request, sphere_tree_collision::Spawn::Response>(
      "spawn", [this](sphere_tree_collision::Spawn::Request& req, sphere_tree_collision::Spawn::Response& res) {
        return spawn(req, res);
      });
  spawn_options.callback_queue = &spawn_queue_;
  servers_.push_back(pnh.advertiseService(spawn_options));
  servers_.push_back(pnh.advertiseService("despawn", &WorldServices::despawn, this));
  servers_.push_back(pnh.advertiseService("clear", &WorldServices::clear, this));
  servers_.push_back(pnh.advertiseService("pause", &WorldServices::pause, this));
  servers_.push_back(pnh.advertiseService("unpause", &WorldServices::unpause, this));
  servers_.push_back(pnh.advertiseService("reset", &WorldServices::reset, this));
  servers_.push_back(pnh.advertiseService("step", &WorldServices::step, this));
  servers_.push_back(pnh.advertiseService("save", &WorldServices::save, this));
}

// A call waiting for the node's spinner gives up, so the spinner's thread can be joined.
WorldServices::~WorldServices() { stopping_ = true; }

void WorldServices::onTickThread(std::function<void()> work) const {
  const auto call = boost::make_shared<TickThreadCall>(std::move(work));
  std::future<void> done = call->done();
  ros::getGlobalCallbackQueue()->addCallback(call);
  while (done.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) {
    if (stopping_ || !ros::ok() || ros::isShuttingDown()) throw std::runtime_error("the node is shutting down");
  }
  done.get();
}

sphere_tree_collision::SpawnEntity WorldServices::inWorldFrame(const sphere_tree_collision::Spawn::Request& req) {
  const std::string& frame = req.header.frame_id;
  if (frame.empty() || frame == world_frame_) return req.entity;
  if (!tf_buffer_) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_);
    tf_since_ = ros::WallTime::now();
  }
  // On ~spawn's own thread: a wait here holds this client's answer, not the
  // ticks. A frame tf has never heard of is refused at once, except while a
  // new listener's buffer fills; a known frame may wait for the stamp.
  const bool filling = (ros::WallTime::now() - tf_since_).toSec() < kTfFillSeconds;
  if (!filling && !tf_buffer_->_frameExists(frame)) {
    throw stc::InputError("header.frame_id", "tf knows no frame \"" + frame + "\"");
  }
  // A stamp tf cannot reach within the wait (or the buffer's length) is refused
  // by name before tf's own time arithmetic overflows on it.
  checkedStampAge(req.header.stamp, ros::Time::now(), tf_buffer_->getCacheLength().toSec(), kTfStampWaitSeconds,
                  "tf keeps " + std::to_string(tf_buffer_->getCacheLength().toSec()) + " s; a spawn waits " +
                      std::to_string(kTfStampWaitSeconds) + " s for a stamp ahead");
  geometry_msgs::TransformStamped t;
  try {
    t = tf_buffer_->lookupTransform(world_frame_, frame, req.header.stamp, ros::Duration(kTfStampWaitSeconds));
  } catch (const tf2::TransformException& e) {
    throw stc::InputError("header.frame_id", e.what());
  }
  const stc::Quat rotation = toEigen(t.transform.rotation).normalized();
  const stc::Vec3 translation = toEigen(t.transform.translation);
  sphere_tree_collision::SpawnEntity m = req.entity;
  // A unit rotation keeps the quaternion's norm: a bad orientation stays bad for the topic's check.
  const stc::Quat q = stc::orientationOrIdentity(toEigen(m.pose.orientation));  // left out: the frame's own
  m.pose.position = toPointMsg(rotation * toEigen(m.pose.position) + translation);
  m.pose.orientation = toQuaternionMsg(rotation * q);
  m.twist.linear = toVector3Msg(rotation * toEigen(m.twist.linear));  // the frame is taken as not moving
  m.twist.angular = toVector3Msg(rotation * toEigen(m.twist.angular));
  return m;
}

bool WorldServices::spawn(sphere_tree_collision::Spawn::Request& req, sphere_tree_collision::Spawn::Response& res) {
  res.id = 0;
  answer(res, "spawn", [&] {
    // Resolved here (tf may wait); the world changed on its own thread. The
    // work holds copies and a shared answer: nothing of this thread's stack.
    const sphere_tree_collision::SpawnEntity entity = inWorldFrame(req);
    struct Made {
      stc::EntityId id = 0;
      std::string frame_id;
    };
    const auto made = std::make_shared<Made>();
    onTickThread([this, entity, made] {
      try {
        made->id = node_.spawnEntity(entity);
      } catch (const stc::InputError& e) {  // named as fields of the request's `entity`
        throw stc::InputError(e.field() == "max_entities" ? e.field() : "entity." + e.field(), e.reason());
      }
      made->frame_id = node_.frameOf(made->id);
      node_.publishEntityList();
    });
    res.id = made->id;
    res.frame_id = made->frame_id;
  });
  return true;  // false would hide the message from the caller
}

bool WorldServices::despawn(sphere_tree_collision::DespawnEntity::Request& req,
                            sphere_tree_collision::DespawnEntity::Response& res) {
  answer(res, "despawn", [&] { node_.despawnEntity(req.id, req.name); });
  if (res.success) node_.publishEntityList();
  return true;
}

bool WorldServices::clear(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  answer(res, "clear", [&] { node_.clearWorld(); });
  node_.publishEntityList();
  return true;
}

bool WorldServices::pause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  answer(res, "pause", [&] { node_.setPaused(true); });
  return true;
}

bool WorldServices::unpause(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  answer(res, "unpause", [&] { node_.setPaused(false); });
  return true;
}

bool WorldServices::reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  answer(res, "reset", [&] { node_.resetWorld(); });
  node_.publishEntityList();
  return true;
}

bool WorldServices::save(sphere_tree_collision::SaveWorld::Request& req,
                         sphere_tree_collision::SaveWorld::Response& res) {
  answer(res, "save", [&] { res.path = node_.saveWorld(req.file); });
  if (!res.success) res.path.clear();
  return true;
}

bool WorldServices::step(sphere_tree_collision::Step::Request& req, sphere_tree_collision::Step::Response& res) {
  answer(res, "step", [&] {
    if (req.ticks == 0 || req.ticks > kMaxStepTicks) {
      throw stc::InputError("ticks", "must be in [1, " + std::to_string(kMaxStepTicks) + "]");
    }
    if (!node_.paused()) throw stc::InputError("ticks", "the world is not paused (call ~pause first)");
    res.tick = node_.queueSteps(req.ticks);
  });
  if (!res.success) res.tick = node_.tickCount();
  return true;
}

}  // namespace stc_ros

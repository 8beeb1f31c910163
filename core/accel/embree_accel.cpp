// Embree types stay in this file. Errors from the device are routed to pt::Error through
// rtcSetDeviceErrorFunction, so a failing build is a clear message rather than a silent black image.
#include "core/accel/embree_accel.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <string>
#include <vector>

#include "core/geometry/intersect.h"
#include "core/geometry/geometry.h"
#include "core/util/error.h"

namespace pt {
namespace {

void on_embree_error(void* user, RTCError code, const char* message) {
  auto* last = static_cast<std::string*>(user);
  *last = "Embree error " + std::to_string(static_cast<int>(code)) + ": " + (message ? message : "");
}

// Embree reports every allocation and release; the running sum is the structure's memory.
bool on_embree_memory(void* user, ssize_t bytes, bool) {
  static_cast<std::atomic<int64_t>*>(user)->fetch_add(bytes);
  return true;
}

void sphere_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* spheres = static_cast<const Sphere*>(args->geometryUserPtr);
  BBox b = spheres[args->primID].bounds();
  args->bounds_o->lower_x = b.lo.x;
  args->bounds_o->lower_y = b.lo.y;
  args->bounds_o->lower_z = b.lo.z;
  args->bounds_o->upper_x = b.hi.x;
  args->bounds_o->upper_y = b.hi.y;
  args->bounds_o->upper_z = b.hi.z;
}

// We only trace single rays (rtcIntersect1/rtcOccluded1), so N is 1; the loop keeps it correct anyway.
void sphere_intersect(const RTCIntersectFunctionNArguments* args) {
  const auto* spheres = static_cast<const Sphere*>(args->geometryUserPtr);
  const Sphere& s = spheres[args->primID];
  RTCRayHitN* rayhit = args->rayhit;
  RTCRayN* rays = RTCRayHitN_RayN(rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    Ray r;
    r.o = {RTCRayN_org_x(rays, args->N, i), RTCRayN_org_y(rays, args->N, i), RTCRayN_org_z(rays, args->N, i)};
    r.d = {RTCRayN_dir_x(rays, args->N, i), RTCRayN_dir_y(rays, args->N, i), RTCRayN_dir_z(rays, args->N, i)};
    r.tmin = RTCRayN_tnear(rays, args->N, i);
    r.tmax = RTCRayN_tfar(rays, args->N, i);
    float t;
    if (!intersect_sphere(r, s.center, s.radius, t)) continue;
    Vec3f n = r.o + r.d * t - s.center;
    RTCRayN_tfar(rays, args->N, i) = t;
    RTCHitN_Ng_x(hits, args->N, i) = n.x;
    RTCHitN_Ng_y(hits, args->N, i) = n.y;
    RTCHitN_Ng_z(hits, args->N, i) = n.z;
    RTCHitN_u(hits, args->N, i) = 0.0f;
    RTCHitN_v(hits, args->N, i) = 0.0f;
    RTCHitN_primID(hits, args->N, i) = args->primID;
    RTCHitN_geomID(hits, args->N, i) = args->geomID;
    RTCHitN_instID(hits, args->N, i, 0) = args->context->instID[0];
  }
}

void sphere_occluded(const RTCOccludedFunctionNArguments* args) {
  const auto* spheres = static_cast<const Sphere*>(args->geometryUserPtr);
  const Sphere& s = spheres[args->primID];
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    Ray r;
    r.o = {RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
           RTCRayN_org_z(args->ray, args->N, i)};
    r.d = {RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
           RTCRayN_dir_z(args->ray, args->N, i)};
    r.tmin = RTCRayN_tnear(args->ray, args->N, i);
    r.tmax = RTCRayN_tfar(args->ray, args->N, i);
    float t;
    if (intersect_sphere(r, s.center, s.radius, t)) RTCRayN_tfar(args->ray, args->N, i) = -kInf;
  }
}

// Instance i is geometry kFirstInstanceId + i of the top scene (after the triangles and spheres).
constexpr unsigned kFirstInstanceId = 2;

class EmbreeAccel final : public Accel {
 public:
  EmbreeAccel(const Geometry& geometry, bool robust) : robust_(robust) {
    auto start = std::chrono::steady_clock::now();
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw Error("Embree: cannot create a device");
    rtcSetDeviceErrorFunction(device_, on_embree_error, &last_error_);
    rtcSetDeviceMemoryMonitorFunction(device_, on_embree_memory, &bytes_allocated_);
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

    const Mesh& mesh = geometry.mesh();
    attach_triangles(scene_, mesh);
    const auto& spheres = geometry.spheres();
    if (!spheres.empty()) {
      RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(spheres.size()));
      rtcSetGeometryUserData(geom, const_cast<Sphere*>(spheres.data()));
      rtcSetGeometryBoundsFunction(geom, sphere_bounds, nullptr);
      rtcSetGeometryIntersectFunction(geom, sphere_intersect);
      rtcSetGeometryOccludedFunction(geom, sphere_occluded);
      rtcCommitGeometry(geom);
      rtcAttachGeometryByID(scene_, geom, kGeomSpheres);
      rtcReleaseGeometry(geom);
    }
    // Each instanced mesh is a scene of its own (its triangles, in its own space) and each instance
    // an instance geometry over that scene, with its transform: Embree takes the ray into the mesh's
    // space, and t keeps its meaning since the transformed direction is not renormalised.
    for (const Geometry& object : geometry.objects()) {
      RTCScene child = rtcNewScene(device_);
      objects_.push_back(child);
      rtcSetSceneFlags(child, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
      rtcSetSceneBuildQuality(child, RTC_BUILD_QUALITY_HIGH);
      attach_triangles(child, object.mesh());
      rtcCommitScene(child);
    }
    const std::vector<Instance>& instances = geometry.instances();
    for (size_t i = 0; i < instances.size(); ++i) {
      RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(geom, objects_[instances[i].mesh]);
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &instances[i].to_world.m[0][0]);
      rtcCommitGeometry(geom);
      rtcAttachGeometryByID(scene_, geom, kFirstInstanceId + static_cast<unsigned>(i));
      rtcReleaseGeometry(geom);
    }
    rtcCommitScene(scene_);
    if (!last_error_.empty()) {
      std::string message = last_error_;
      release();
      throw Error(message);
    }
    stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats_.primitives = geometry.world_triangle_count() + spheres.size();
    stats_.bytes = static_cast<size_t>(std::max<int64_t>(0, bytes_allocated_.load()));
  }
  ~EmbreeAccel() override { release(); }

  std::optional<Hit> intersect(const Ray& ray) const override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = ray.o.x;
    rh.ray.org_y = ray.o.y;
    rh.ray.org_z = ray.o.z;
    rh.ray.dir_x = ray.d.x;
    rh.ray.dir_y = ray.d.y;
    rh.ray.dir_z = ray.d.z;
    rh.ray.tnear = ray.tmin;
    rh.ray.tfar = ray.tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
      return Hit{rh.ray.tfar, kGeomTriangles, rh.hit.primID, rh.hit.u, rh.hit.v, rh.hit.instID[0] - kFirstInstanceId};
    }
    return Hit{rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v};
  }

  bool occluded(const Ray& ray) const override {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r;
    r.org_x = ray.o.x;
    r.org_y = ray.o.y;
    r.org_z = ray.o.z;
    r.dir_x = ray.d.x;
    r.dir_y = ray.d.y;
    r.dir_z = ray.d.z;
    r.tnear = ray.tmin;
    r.tfar = ray.tmax;
    r.time = 0.0f;
    r.mask = ~0u;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene_, &context, &r);
    return r.tfar < 0.0f;
  }

  AccelStats stats() const override { return stats_; }
  std::string name() const override { return robust_ ? "embree-robust" : "embree"; }

 private:
  // The mesh's triangles as geometry kGeomTriangles of `scene`, sharing the mesh's buffers.
  void attach_triangles(RTCScene scene, const Mesh& mesh) {
    if (mesh.triangle_count() == 0) return;
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.positions.data(), 0,
                               sizeof(Vec3f), mesh.positions.size());
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.indices.data(), 0,
                               3 * sizeof(uint32_t), mesh.triangle_count());
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene, geom, kGeomTriangles);
    rtcReleaseGeometry(geom);
  }
  void release() {
    if (scene_) rtcReleaseScene(scene_);
    for (RTCScene child : objects_) rtcReleaseScene(child);
    objects_.clear();
    if (device_) rtcReleaseDevice(device_);
    scene_ = nullptr;
    device_ = nullptr;
  }
  bool robust_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<RTCScene> objects_;  // one per instanced mesh
  std::string last_error_;
  std::atomic<int64_t> bytes_allocated_{0};
  AccelStats stats_;
};

}  // namespace

std::unique_ptr<Accel> make_embree_accel(const Geometry& geometry, bool robust) {
  return std::make_unique<EmbreeAccel>(geometry, robust);
}

}  // namespace pt

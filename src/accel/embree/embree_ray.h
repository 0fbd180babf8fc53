// Our Ray as an Embree 3 RTCRay (shared by the Embree backend and the benchmarks that call Embree
// directly, so both trace exactly the same rays).
#pragma once

#include <embree3/rtcore.h>

#include "accel/accelerator.h"

namespace whitted {

/// Fills `r` from `ray`: origin, direction, [tnear, tfar], time 0, all mask bits, id and flags 0.
inline void set_rtc_ray(RTCRay& r, const Ray& ray) {
    r.org_x = ray.org.x;
    r.org_y = ray.org.y;
    r.org_z = ray.org.z;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tnear = ray.tnear;
    r.tfar = ray.tfar;
    r.time = 0.f;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
}

/// Fills lane `i` of an RTCRay4/8/16 packet as set_rtc_ray does (the caller sets the id).
template <class RTCRayK>
inline void set_rtc_lane(RTCRayK& r, int i, const Ray& ray) {
    r.org_x[i] = ray.org.x;
    r.org_y[i] = ray.org.y;
    r.org_z[i] = ray.org.z;
    r.dir_x[i] = ray.dir.x;
    r.dir_y[i] = ray.dir.y;
    r.dir_z[i] = ray.dir.z;
    r.tnear[i] = ray.tnear;
    r.tfar[i] = ray.tfar;
    r.time[i] = 0.f;
    r.mask[i] = 0xffffffffu;
    r.id[i] = 0;
    r.flags[i] = 0;
}

}  // namespace whitted

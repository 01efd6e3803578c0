/* The host <-> kernel parameter structs of the OpenCL backend, defined once and compiled by
 * both sides: the C++ host (sdk/src/opencl/, which static_asserts the layout) and OpenCL C
 * (the backend prepends this file to every program it builds).
 *
 * Only 4- and 8-byte scalars and arrays of them, every struct a multiple of 8 bytes with
 * its 8-byte fields 8-aligned, so the layout is the same for any host and device compiler.
 * Doubles travel as their bit patterns (ulong): a device without cl_khr_fp64 can still read
 * the struct (and converts them to float, losing the exact parity with the CPU backend). */
#ifndef FLURRY_KERNELS_PARAMS_H
#define FLURRY_KERNELS_PARAMS_H

#ifdef __OPENCL_VERSION__
typedef uint fl_u32;
typedef ulong fl_u64;
#else
#include <cstdint>
namespace flurry::detail::cl {
typedef std::uint32_t fl_u32;
typedef std::uint64_t fl_u64;
#endif

/* Domain kinds, in the order of flurry::Domain::Shape's alternatives. */
#define FL_DOMAIN_POINT 0
#define FL_DOMAIN_LINE 1
#define FL_DOMAIN_TRIANGLE 2
#define FL_DOMAIN_PLANE 3
#define FL_DOMAIN_RECTANGLE 4
#define FL_DOMAIN_DISC 5
#define FL_DOMAIN_BOX 6
#define FL_DOMAIN_SPHERE 7
#define FL_DOMAIN_CYLINDER 8
#define FL_DOMAIN_CONE 9
#define FL_DOMAIN_BLOB 10
/* Their data lives in a table of floats (emission: the step's shape table; actions: the
 * list's `extra`), at the offset their FlDomain holds (see emission.hpp ShapePacker). */
#define FL_DOMAIN_MESH 11
#define FL_DOMAIN_UNION 12

/* A domain to sample from or to test against. v[] by kind (vectors are 3 floats):
 *  point p | line p0 p1 | triangle p0 p1 p2 | plane point normal | rectangle origin u v
 *  disc center e1 e2 outer inner | box min max | sphere center outer inner
 *  cylinder p0 axis e1 e2 outer inner | cone apex axis e1 e2 outer inner | blob center stddev
 * (e1, e2: the basis around the normal or axis, computed on the host exactly as the CPU's
 * sampler does, so both draw the same points.) */
typedef struct FlDomain {
  float v[16];
  fl_u32 kind;
  fl_u32 pad;
} FlDomain;

/* A fuzzy scalar: center +- spread, uniform or normal. */
typedef struct FlFuzzy {
  float center;
  float spread;
  fl_u32 normal;
  fl_u32 pad;
} FlFuzzy;

typedef struct FlParticleType {
  FlDomain velocity, color, up, rotVelocity;
  FlFuzzy alpha, size, mass, lifetime, charge;
  float weight;
  fl_u32 pad;
} FlParticleType;

typedef struct FlEmitter {
  FlDomain shape;
  fl_u64 start;    /* double bits: the emitter's start time */
  fl_u64 rate;     /* double bits: particles per second */
  float position[4];
  float velocity[4];
  FlFuzzy normalSpeed;         /* Emitter::normalSpeed */
  fl_u32 pathFirst, pathCount; /* keyframes [pathFirst, pathFirst + pathCount) */
  fl_u32 typeFirst, typeCount; /* types [typeFirst, typeFirst + typeCount) */
  float totalWeight;           /* the types' weights summed in order, as the CPU does */
  fl_u32 variant;              /* the case of the generated fl_emit for its kinds */
  fl_u32 pathLoop;             /* Emitter::pathLoop: 1 repeats the path after its last key */
  fl_u32 pad;
} FlEmitter;

typedef struct FlKeyframe {
  fl_u64 time; /* double bits */
  float position[4];
} FlKeyframe;

/* One run of births of one emitter this step (sdk/src/emission.cpp BirthRun). */
#define FL_RUN_RATE 0u
#define FL_RUN_BURST 1u
#define FL_RUN_DISTANCE 2u
typedef struct FlBirthRun {
  fl_u64 first; /* rate: index of the run's first birth since the emitter's start */
  fl_u64 time;  /* double bits: a burst's time; distance: the step's start */
  fl_u64 start; /* index of the run's first newborn among this step's births */
  fl_u64 s0, spacing, span, dt; /* distance, double bits: births at time + dt (s0 + q
                                   spacing) / span */
  fl_u32 emitter; /* index into the step's emitter table */
  fl_u32 kind;    /* FL_RUN_* */
} FlBirthRun;

/* ---- Each action's constants, by name --------------------------------------------------
 * Made on the host by one maker for both backends (actionParams, sdk/src/action_params.hpp)
 * and read by the action's kernel function (forces.h, deflect.h, ...), which the CPU's pass
 * and the device's act kernel both call. A `decay` is exp(-rate * dt) made with fl_expf for
 * the record's `dt`, so both backends multiply by the same bits; a step of another length (a
 * newborn's rest of its step, a sub-step on the device) makes its own. */

/* Three floats (OpenCL's float3 takes the room of four). */
typedef struct FlXyz {
  float x, y, z;
} FlXyz;

typedef struct FlGravityParams {
  FlXyz acceleration;
} FlGravityParams;

/* Damping and RotDamping. */
typedef struct FlDampingParams {
  FlXyz decay, rate;
  float dt;
} FlDampingParams;

typedef struct FlOrbitPointParams {
  FlXyz center;
  float magnitude, epsilon, maxRadius;
} FlOrbitPointParams;

typedef struct FlOrbitLineParams {
  FlXyz point, axis; /* axis: unit, normalised as the CPU does */
  float magnitude, epsilon, maxRadius;
} FlOrbitLineParams;

typedef struct FlVortexParams {
  FlXyz center, axis; /* axis: unit */
  float aroundSpeed, coreRadius, tightness, inSpeed, upSpeed, maxRadius;
  float responsiveness, dt, decay;
} FlVortexParams;

/* Jet: the ball it acts in (its acceleration is the action's domain). */
typedef struct FlJetParams {
  FlXyz center;
  float radius;
} FlJetParams;

typedef struct FlExplosionParams {
  FlXyz center;
  float speed, magnitude, epsilon, time;
  float invTwoVariance; /* 1 / (2 stddev^2), apply()'s */
  float twoVariance;    /* 2 stddev^2, accumulate()'s */
} FlExplosionParams;

typedef struct FlTurbulenceParams {
  float amplitude, frequency;
  FlXyz drift;
  fl_u32 octaves;
} FlTurbulenceParams;

typedef struct FlElectricParams {
  FlXyz field;
} FlElectricParams;

typedef struct FlMagneticParams {
  FlXyz direction; /* field / |field|, 0 for no field */
  float strength;  /* |field| */
  FlXyz field;
} FlMagneticParams;

/* SampledField: the grid's samples (xyz each, x fastest) in the list's `extra` from `first`. */
typedef struct FlSampledFieldParams {
  FlXyz origin;
  float voxelSize, strength, responsiveness, dt, decay;
  fl_u32 first, nx, ny, nz;
  fl_u32 carry; /* 1 for Mode::Velocity: carried towards the field */
} FlSampledFieldParams;

/* TargetVelocity, TargetRotVelocity, TargetColor, TargetSize: the target (a vector's three,
 * or colour and alpha, or a size), approached at `rate`. */
typedef struct FlTargetParams {
  float target[4];
  float rate, dt, decay;
} FlTargetParams;

typedef struct FlSpeedClampParams {
  float minSpeed, maxSpeed;
} FlSpeedClampParams;

/* ColorOverLife, SizeOverLife: `keys` keys in the list's `extra` from `first`, each its t
 * then its value (r g b a, or a size). */
typedef struct FlCurveParams {
  fl_u32 first, keys;
} FlCurveParams;

/* Restore: its start and start + duration, doubles as their bits. */
typedef struct FlRestoreParams {
  fl_u64 start, end;
} FlRestoreParams;

/* Bounce, as both backends prepare it (sdk/src/actions.cpp bounceParams): the plane of a
 * planar piece (a segment's wall: its normal in the group's plane), or a sphere's center as
 * `point`; on the device the surface itself is also the action's domain (boxes, and the
 * integrators' guard). The planar pieces, as deflect.h fl_on_piece tells them: */
#define FL_PIECE_PLANE 0
#define FL_PIECE_RECTANGLE 1
#define FL_PIECE_TRIANGLE 2
#define FL_PIECE_DISC 3
#define FL_PIECE_SEGMENT 4
typedef struct FlBounceParams {
  FlXyz point, normal;
  float restitution, keep /* 1 - friction */, cutoff2;
  union FlBouncePiece {
    struct FlBounceDual {
      FlXyz u, v; /* rectangle, triangle: the dual vectors of its edges */
    } dual;
    struct FlBounceDisc {
      float outer2, inner2;
    } disc;
    struct FlBounceSegment {
      FlXyz direction;
      float length2;
    } segment;
    struct FlBounceSphere {
      float radius, radius2, invRadius;
      float reach; /* |center|_1 + radius */
    } sphere;
  } piece;
} FlBounceParams;

/* Sink: the chance that a particle it takes passes it. */
typedef struct FlSinkParams {
  float passThrough;
} FlSinkParams;

typedef struct FlAvoidParams {
  float magnitude, epsilon, lookAhead;
} FlAvoidParams;

typedef struct FlConstrain2DParams {
  FlXyz point, normal; /* normal: unit */
} FlConstrain2DParams;

/* Gravitate and Follow: a soft pull. */
typedef struct FlPullParams {
  float magnitude, epsilon, maxRadius2;
} FlPullParams;

/* MatchVelocity, MatchRotVelocity: `approach` is 1 - exp(-rate * dt). */
typedef struct FlMatchParams {
  float rate, dt, maxRadius2, approach;
} FlMatchParams;

/* A force's falloff (forces.h fl_falloff_weight). */
typedef struct FlFalloffParams {
  float cx, cy, cz, radius, power;
} FlFalloffParams;

/* One action's constants. `domain` holds its region, surface or sampled domain (fl_sample
 * and fl_inside read it directly); data longer than its own (keys over life, a mesh's or
 * union's data, grids) goes into the list's `extra` floats, at offsets its own record or
 * its domain holds. */
typedef struct FlActionParams {
  FlDomain domain;
  union FlActionOwn {
    float raw[24]; /* the size; first, so that value-initialising zeroes it all */
    FlGravityParams gravity;
    FlDampingParams damping;
    FlOrbitPointParams orbitPoint;
    FlOrbitLineParams orbitLine;
    FlVortexParams vortex;
    FlJetParams jet;
    FlExplosionParams explosion;
    FlTurbulenceParams turbulence;
    FlElectricParams electric;
    FlMagneticParams magnetic;
    FlSampledFieldParams sampledField;
    FlTargetParams target;
    FlSpeedClampParams speedClamp;
    FlCurveParams curve;
    FlRestoreParams restore;
    FlBounceParams bounce;
    FlSinkParams sink;
    FlAvoidParams avoid;
    FlConstrain2DParams constrain2d;
    FlPullParams pull;
    FlMatchParams match;
  } own;
  FlFalloffParams falloff; /* a force's, where it has one */
  fl_u32 pad;
} FlActionParams;

/* The group's device-side state: one small buffer of uints, read back asynchronously after
 * every step (the host never waits for it, except when someone reads the particles). */
#define FL_STATE_SIZE 0     /* live particles after the step */
#define FL_STATE_NEXT_ID 1  /* the next particle id */
#define FL_STATE_DROPPED 2  /* births dropped at capacity, cumulative (wraps; host sums deltas) */
#define FL_STATE_OLD_SIZE 3 /* this step: live before it */
#define FL_STATE_DEAD 4     /* this step: died */
#define FL_STATE_BORN 5     /* this step: born */
#define FL_STATE_LOW_HOLES 6 /* this step: holes below the new size */
#define FL_STATE_FIRST_ID 7 /* this step: the first newborn's id */
#define FL_STATE_SUBSTEPS 8 /* this step: sub-steps (Substeps::maxDistance), from fl_max_speed */
#define FL_STATE_MAX_SPEED2 9 /* this step: the largest |v|^2, as float bits (atomic_max) */
#define FL_STATE_HAIR_ALIVE 10 /* hair: strands whose particle outlived maxVertices (cumulative) */
#define FL_STATE_CULLED 11 /* work-group x actions skipped by culling (cumulative, wraps) */
#define FL_STATE_KILLS 12   /* then one cumulative (wrapping) kill counter per kill code */
#define FL_STATE_HEADER 12
#define FL_KILL_CODES 255   /* codes 1..255: 1 + the killing action, 255 non-finite */
#define FL_NON_FINITE_CODE 255

/* Work-items per work-group of fl_act and fl_small (their culling reduces over it). */
#define FL_ACT_LOCAL 256
/* Particles each work-item of fl_small acts on (one after another, without culling): its one
 * work-group covers FL_ACT_LOCAL * FL_SMALL_RUN, every particle of a group it steps. */
#define FL_SMALL_RUN 16

/* Spatial culling: per action, FL_REACH_FLOATS floats in the list's `extra` (from the
 * argument reachOff on): its reach box lo x y z, hi x y z, the box's max |coordinate| and the
 * margin's quadratic term (ActionPlan::Reach), a scale < 0 when the action has no finite
 * reach; [8] 1 when the bounds need not be gathered again after it (a Bounce that slows,
 * a Damping, a Gravity of weight <= 1), [9] a Gravity's |acceleration|, summed over axes. */
#define FL_REACH_FLOATS 10

/* Particles per tile of the death count and the hole list (a multiple of 16: counted as
 * uint4 words). */
#define FL_TILE 1024

/* Neighbour actions read the particles as they were at the start of the step: component c
 * (x y z) of attribute a (0 position, 1 velocity, 2 angular velocity) of particle j. */
#define FL_SNAP(a, c, j) snap[((a) * 3u + (c)) * snapStride + (j)]

#ifndef __OPENCL_VERSION__
}  // namespace flurry::detail::cl
#endif

#endif /* FLURRY_KERNELS_PARAMS_H */

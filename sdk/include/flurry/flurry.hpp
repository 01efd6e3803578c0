// Flurry: a particle-system SDK. Include this one header.
#pragma once

#include "flurry/actions.hpp"
#include "flurry/attribute.hpp"
#include "flurry/context.hpp"
#include "flurry/domain.hpp"
#include "flurry/emitter.hpp"
#include "flurry/error.hpp"
#include "flurry/field.hpp"
#include "flurry/fuzzy.hpp"
#include "flurry/group.hpp"
#include "flurry/interop.hpp"
#include "flurry/io.hpp"
#include "flurry/log.hpp"
#include "flurry/math.hpp"
#include "flurry/random.hpp"
#include "flurry/strands.hpp"
#include "flurry/version.hpp"

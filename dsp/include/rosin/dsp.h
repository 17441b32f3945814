// Umbrella header of the real-time model library.
#pragma once
#include "rosin/dsp/Body.h"
#include "rosin/dsp/BowGesture.h"
#include "rosin/dsp/BowJunction.h"
#include "rosin/dsp/BowedString.h"
#include "rosin/dsp/Config.h"
#include "rosin/dsp/DelayLine.h"
#include "rosin/dsp/FrictionLaws.h"
#include "rosin/dsp/ReflectionFilter.h"
#include "rosin/dsp/StringParams.h"
#include "rosin/dsp/StringWaveguide.h"
#include "rosin/dsp/TemperatureLaw.h"
#include "rosin/dsp/ThermalContact.h"

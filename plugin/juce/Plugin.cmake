# JUCE plugin (VST3, LV2, Standalone) and the headless host. Debian's JUCE 7.0.5: no version
# in find_package, LV2URI needs the JucePlugin_LV2URI define too, no FLAC/Vorbis without LTO.
find_package(JUCE CONFIG REQUIRED)
find_package(CLI11 REQUIRED)
set(ROSIN_JUCE_DEFINITIONS
  JUCE_WEB_BROWSER=0 JUCE_USE_CURL=0 JUCE_USE_FLAC=0 JUCE_USE_OGGVORBIS=0 JUCE_JACK=1
  JUCE_DISPLAY_SPLASH_SCREEN=0 JUCE_REPORT_APP_USAGE=0)
set(ROSIN_LV2_URI "http://rosin-synth.org/plugins/rosin")

juce_add_plugin(RosinPlugin
  PRODUCT_NAME "Rosin"
  COMPANY_NAME "Rosin"
  BUNDLE_ID org.rosin-synth.rosin
  PLUGIN_MANUFACTURER_CODE Rosn
  PLUGIN_CODE Rsn1
  FORMATS VST3 LV2 Standalone
  IS_SYNTH TRUE
  NEEDS_MIDI_INPUT TRUE
  NEEDS_MIDI_OUTPUT FALSE
  IS_MIDI_EFFECT FALSE
  EDITOR_WANTS_KEYBOARD_FOCUS FALSE
  VST3_CATEGORIES Instrument Synth
  LV2URI ${ROSIN_LV2_URI}
  COPY_PLUGIN_AFTER_BUILD FALSE)

target_sources(RosinPlugin PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/RosinProcessor.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/RosinProcessorPresets.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/StateFormat.cpp
  ${PROJECT_SOURCE_DIR}/ui/RosinEditor.cpp
  ${PROJECT_SOURCE_DIR}/ui/LiveViews.cpp)
target_include_directories(RosinPlugin PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src ${PROJECT_SOURCE_DIR}/ui)
target_compile_definitions(RosinPlugin PUBLIC ${ROSIN_JUCE_DEFINITIONS}
  JucePlugin_LV2URI="${ROSIN_LV2_URI}"
  JUCE_VST3_CAN_REPLACE_VST2=0)
target_link_libraries(RosinPlugin
  PRIVATE rosin::engine rosin::hid rosin_lab_core juce::juce_audio_utils juce::juce_audio_plugin_client ${CMAKE_DL_LIBS}
  PUBLIC juce::juce_recommended_config_flags juce::juce_recommended_warning_flags)
# GCC 12 takes JUCE 7.0.5's ListenerList iterator, which links itself into the list and unlinks in
# its destructor, for a dangling pointer in every JUCE module compiled here; and the dsp headers'
# four-double vectors draw the AVX calling-convention note (see the top-level CMakeLists.txt).
foreach(target RosinPlugin RosinPlugin_VST3 RosinPlugin_LV2 RosinPlugin_Standalone)
  target_compile_options(${target} PRIVATE -Wno-dangling-pointer -Wno-psabi)
endforeach()

# Debian JUCE 7.0.5 quirk: enumerated LV2 parameters get normalised scale points (see the script).
get_target_property(ROSIN_LV2_DIR RosinPlugin_LV2 LIBRARY_OUTPUT_DIRECTORY)
add_executable(rosin_fix_lv2_scale_points ${CMAKE_CURRENT_SOURCE_DIR}/juce/fix_lv2_scale_points.cpp)
add_dependencies(RosinPlugin_LV2 rosin_fix_lv2_scale_points)
add_custom_command(TARGET RosinPlugin_LV2 POST_BUILD
  COMMAND rosin_fix_lv2_scale_points ${ROSIN_LV2_DIR}/dsp.ttl
  VERBATIM)

# Headless host core: JUCE plugin hosting compiled once, behind a JUCE-free header.
add_library(rosin_host_core STATIC ${CMAKE_CURRENT_SOURCE_DIR}/host/PluginHost.cpp)
target_include_directories(rosin_host_core PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/host)
target_compile_definitions(rosin_host_core PRIVATE ${ROSIN_JUCE_DEFINITIONS}
  JUCE_PLUGINHOST_VST3=1 JUCE_PLUGINHOST_LV2=1 JUCE_STANDALONE_APPLICATION=1 JUCE_MODAL_LOOPS_PERMITTED=1
  JUCE_GLOBAL_MODULE_SETTINGS_INCLUDED=1)
find_package(PkgConfig REQUIRED)
pkg_check_modules(ROSIN_IMAGE_LIBS REQUIRED IMPORTED_TARGET libpng libjpeg)
target_link_libraries(rosin_host_core PRIVATE juce::juce_audio_processors juce::juce_audio_formats
  PUBLIC PkgConfig::ROSIN_IMAGE_LIBS)
# The host only loads and drives the plugin, whose own code is built at -O3: JUCE's hosting and GUI
# at -O1 take a third less time to build (the second JUCE in the tree) and run the same tests.
target_compile_options(rosin_host_core PRIVATE $<$<CONFIG:Release>:-O1>)
target_compile_features(rosin_host_core PUBLIC cxx_std_20)

# The audit counter interposes malloc/pthread_mutex_lock: executables export it (-rdynamic)
# so the dlopen'ed plugin binds to it.
add_executable(rosin-host ${CMAKE_CURRENT_SOURCE_DIR}/host/HostMain.cpp ${CMAKE_CURRENT_SOURCE_DIR}/host/AuditCounter.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/host/Validate.cpp)
target_link_libraries(rosin-host PRIVATE rosin_host_core rosin::hid rosin::presets CLI11::CLI11 nlohmann_json::nlohmann_json ${CMAKE_DL_LIBS})
set_target_properties(rosin-host PROPERTIES ENABLE_EXPORTS ON)
add_dependencies(rosin-host RosinPlugin_VST3 RosinPlugin_LV2)

get_target_property(ROSIN_VST3_BUNDLE RosinPlugin_VST3 JUCE_PLUGIN_ARTEFACT_FILE)
get_target_property(ROSIN_LV2_BUNDLE RosinPlugin_LV2 JUCE_PLUGIN_ARTEFACT_FILE)
set(ROSIN_VST3_BUNDLE ${ROSIN_VST3_BUNDLE} PARENT_SCOPE)
set(ROSIN_LV2_BUNDLE ${ROSIN_LV2_BUNDLE} PARENT_SCOPE)
set(ROSIN_VST3_BUNDLE ${ROSIN_VST3_BUNDLE})
set(ROSIN_LV2_BUNDLE ${ROSIN_LV2_BUNDLE})
install(TARGETS rosin-host RUNTIME DESTINATION bin)

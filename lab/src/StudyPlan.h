// A study's plan.json as the study's two halves share it (Study.cpp runs a plan, StudyScore.cpp
// scores it): read from its folder, and the part of it that names the population its sets come
// from. Internal to lab/.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace rosin::lab {

/// DIR/plan.json, or null when the folder has none; an unreadable one is refused naming the file.
nlohmann::json readPlan(const std::filesystem::path& dir);
/// The folder a study keeps set `index` in (DIR/sets/NNN).
std::filesystem::path setFolder(const std::filesystem::path& dir, int index);

/// What a set's diagnosis/split.json says of its split: the seed (0 where none was written) and
/// the method (diagnoses from before the stratified split wrote none and were all "random").
struct SplitRecord {
    std::uint64_t seed = 0;
    std::string method = "random";
};
/// Reads a split.json; an unreadable one is refused naming the file.
SplitRecord readSplitRecord(const std::filesystem::path& file);

/// A diagnosis.json's "search" switches (searchSwitches), empty where the diagnosis predates the
/// record and so cannot be checked; a malformed record is refused naming `file`, where it was read.
std::map<std::string, bool> searchRecordOf(const nlohmann::json& diagnosis, const std::filesystem::path& file);
/// "contact_restart on, pairs off, second_start off" (the switches in name order), or "not
/// recorded" for an empty record.
std::string describeSearch(const std::map<std::string, bool>& search);
/// A diagnosis.json's metric weights; a diagnosis from before they were recorded ran with the
/// metric's own (ErrorParts::kWeights). A malformed record is refused naming `file`.
std::array<double, 5> metricWeightsOf(const nlohmann::json& diagnosis, const std::filesystem::path& file);
/// "0.25/0.25/0.25/0.1/0.15 (the default)", or without the remark for other weights.
std::string describeMetricWeights(const std::array<double, 5>& weights);

/// What must match for studies to be scored as one: the strokes, the rig population and the
/// effects' size ranges (a study of narrowed sizes would skew a pooled detection rate). The seed,
/// the number of sets and the plan version may differ (a plan of either version draws its sets
/// from the same population of rigs and effects).
nlohmann::json populationOf(const nlohmann::json& plan);

} // namespace rosin::lab

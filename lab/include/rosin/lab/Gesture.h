// Bow gestures as functions of time: the strokes of PHYSICS.md 6.1, or rows read from a file.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace rosin::lab {

enum class GestureKind {
    Guettler,      ///< constant force, speed a*t from rest
    Constant,      ///< constant force and speed from t = 0 (sudden start)
    ExpSpeed,      ///< "modified Guettler": v = v0 (1 - exp(-t / tv)), constant force
    ExpForce,      ///< "string crossing": F = F0 (1 - exp(-t / tf)), constant speed
    File           ///< time, force, speed, beta rows, linear in between
};

struct GestureRow {
    double time, force, speed, beta;
};

struct Gesture {
    GestureKind kind = GestureKind::Guettler;
    double force = 1.0;        ///< N (F0 for ExpForce)
    double acceleration = 1.0; ///< m/s^2 (Guettler)
    double speed = 0.1;        ///< m/s (Constant, ExpForce; v0 for ExpSpeed)
    double timeConstant = 0.02;///< s (tv for ExpSpeed, tf for ExpForce)
    double beta = 0.0899;
    std::vector<GestureRow> rows; ///< File

    struct Controls {
        double force, speed, beta;
    };
    Controls at(double t) const noexcept;

    /// The stroke's horizontal coordinate in its gesture's plane: bow acceleration (Guettler),
    /// initial acceleration v0/tv (ExpSpeed), bow speed (ExpForce, Constant); 0 for a file.
    double drive() const noexcept;

    /// Natural length: the last row's time for a file, otherwise 0 (caller chooses).
    double naturalDuration() const noexcept { return rows.empty() ? 0.0 : rows.back().time; }
};

GestureKind parseGestureKind(const std::string& name); ///< throws LabError

/// Reads a gesture CSV: optional '#' comments, a header naming time,force,speed,beta (any
/// order), then rows with strictly increasing time. Throws LabError with file:line: field.
std::vector<GestureRow> loadGestureFile(const std::filesystem::path& file);

} // namespace rosin::lab

#pragma once
// The schema of hystlab.db, versioned by PRAGMA user_version, with forward migrations.
#include "hystlab/db/sqlite.hpp"

namespace hystlab::db {

inline constexpr int kSchemaVersion = 6;

// Brings the file to kSchemaVersion in one transaction per step. Throws DbError for a file
// newer than this program (refusing to guess), or when a migration fails (rolled back).
void migrate(Database& db);
[[nodiscard]] int schema_version(Database& db);

}  // namespace hystlab::db

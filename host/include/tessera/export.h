#pragma once

// Symbols that must be shared between the host and plugins (interfaces whose
// type_info crosses the boundary, exceptions thrown by plugins) are exported on
// purpose; plugins are otherwise built with hidden visibility.
#define TESSERA_API __attribute__((visibility("default")))

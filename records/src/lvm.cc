#include "raw_table.h"

#pragma once
#include <maya/MayaApiStub.h>

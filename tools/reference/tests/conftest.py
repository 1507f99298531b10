# SPDX-License-Identifier: Apache-2.0
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))                    # tools/reference
sys.path.insert(0, os.path.dirname(os.path.dirname(HERE)))   # tools (convert_checkpoint)

#!/usr/bin/env python3
"""Frames into PyTorch without a copy: a turntable rendered on the GPU, each frame's colour, ids and
depth handed to torch through DLPack (torch.from_dlpack shares the renderer's memory), and a tensor
computed from them on the GPU. On a machine without CUDA the frames come back as host arrays and
torch.from_dlpack shares those instead.

    python3 examples/python/torch_frames.py --frames 60 --width 640 --height 360
"""

import argparse

import torch

import raster


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", default="builtin")
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    args = parser.parse_args()

    renderer = raster.Renderer()
    on_device = renderer.device.backend == "cuda"
    scene = raster.Scene.load(args.scene)
    coverage = []
    for k in range(args.frames):
        frame = renderer.render(scene, args.width, args.height, f"orbit:{360.0 * k / args.frames},20,2.5r",
                                on_device=on_device)
        color = torch.from_dlpack(frame.color)  # (H, W, 4) uint8, the frame's own memory
        # (H, W) uint32, seen as int32 (few torch operations take uint32): EMPTY_ID is -1 there.
        ids = torch.from_dlpack(frame.ids).view(torch.int32)
        depth = torch.from_dlpack(frame.depth)  # (H, W) float32
        covered = ids != -1
        coverage.append(covered.float().mean())
        if k == 0:
            where = color.device
            print(f"frame 0: colour {tuple(color.shape)} {color.dtype} on {where}, "
                  f"nearest depth {depth[covered].min().item():.4f}")
    print(f"{args.frames} frames on {renderer.device.name}: mean coverage "
          f"{torch.stack(coverage).mean().item():.3f}")


if __name__ == "__main__":
    main()

#!/bin/bash
# usage: MIRROR=GITDIR OUT=DIR bash extract_xcist.sh
# extract a TCIA DICOM series (default: body = CPTAC-PDA chest; SERIES="head neck abdomen" for the others) from the xcist/phantoms-voxelized mirror
set -e
R=${MIRROR:?the git directory of a github.com/xcist/phantoms-voxelized clone}; O=${OUT:-.}/src/xcist
cd $R
for ser in ${SERIES:-body}; do
  mkdir -p $O/$ser
  git ls-tree -r HEAD DICOM_to_voxelized | grep "example_${ser}_DICOMs" | grep '\.dcm$' | while IFS=$'\t' read meta path; do
     blob=$(echo $meta | awk '{print $3}'); git cat-file blob $blob > "$O/$ser/$(basename "$path")"; done
done
